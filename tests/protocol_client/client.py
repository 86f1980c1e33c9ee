#!/usr/bin/env python3
"""A triad link client written from docs/PROTOCOL.md alone (issue 26).

Nothing here is taken from the project's code: framing (section 2), CRC-32C
(section 4), data frames (section 3), packets (section 12), sessions (13),
commands (15), replies (16), identify (17), the calibration blob (21). It
talks to a board on the serial port given as the first argument (the
emulated board behind `xtask serve --storage FILE`, storage erased at
start) and checks what the document promises. Python 3 standard library
only. Prints one line per check; exits 1 when any fails.

Run by host/tests/device_qemu.rs (`cargo xtask test`).
"""

import os
import select
import struct
import sys
import termios
import time
import tty

# Section 4: CRC-32C (Castagnoli), reflected, init and final XOR 0xFFFFFFFF.
def _crc_table():
    table = []
    for n in range(256):
        c = n
        for _ in range(8):
            c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
        table.append(c)
    return table


CRC_TABLE = _crc_table()


def crc32c(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc = CRC_TABLE[(crc ^ b) & 0xFF] ^ (crc >> 8)
    return crc ^ 0xFFFFFFFF


# Section 2: COBS.
def stuff(data):
    out = bytearray([0])
    code_at, code = 0, 1
    for b in data:
        if b == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
        else:
            out.append(b)
            code += 1
            if code == 0xFF:
                out[code_at] = code
                code_at, code = len(out), 1
                out.append(0)
    out[code_at] = code
    return bytes(out)


def unstuff(data):
    """The bytes between two 0x00, unstuffed; None when broken."""
    out = bytearray()
    i = 0
    while i < len(data):
        code = data[i]
        if i + code > len(data):
            return None
        out += data[i + 1:i + code]
        i += code
        if code < 0xFF and i < len(data):
            out.append(0)
    return bytes(out)


def seal(body):
    return body + struct.pack("<I", crc32c(body))


def wire(packet):
    return stuff(packet) + b"\x00"


STATUS = {0: "ok", 1: "bad CRC", 2: "wrong version", 3: "unknown command",
          4: "malformed", 5: "invalid calibration", 6: "storage failure",
          7: "busy", 8: "bad argument", 9: "not supported", 10: "sensor error"}


class Board:
    """The port, the bytes read, and a sequence number (section 13)."""

    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        termios.tcflush(self.fd, termios.TCIOFLUSH)
        self.pending = bytearray()
        self.sequence = 0x100
        self.frames = []       # good version-1 data frames, in order
        self.skipped = 0       # packets that failed their checks
        os.write(self.fd, b"\x00")

    def close(self):
        os.close(self.fd)

    def packets(self, deadline):
        """Unstuffed, CRC-checked packets until `deadline`."""
        while True:
            while b"\x00" in self.pending:
                at = self.pending.index(0)
                chunk, self.pending = bytes(self.pending[:at]), self.pending[at + 1:]
                if not chunk:
                    continue
                packet = unstuff(chunk)
                if packet is None or len(packet) < 5 or len(packet) > 240:
                    self.skipped += 1
                    continue
                if crc32c(packet[:-4]) != struct.unpack("<I", packet[-4:])[0]:
                    self.skipped += 1
                    continue
                if packet[0] == 1 and len(packet) == 51:
                    self.frames.append(packet)
                yield packet
            left = deadline - time.monotonic()
            if left <= 0:
                return
            ready, _, _ = select.select([self.fd], [], [], left)
            if ready:
                self.pending += os.read(self.fd, 4096)

    def exchange(self, packet, sequence, timeout=0.5, tries=6):
        """Sends `packet`, resending the same bytes on a timeout, until the
        reply numbered `sequence` arrives: (code, status, payload)."""
        for _ in range(tries):
            os.write(self.fd, wire(packet))
            for p in self.packets(time.monotonic() + timeout):
                if p[0] == 2 and p[1] == 0x03 and len(p) >= 10:
                    seq, code, status = struct.unpack("<HBB", p[2:6])
                    if seq == sequence:
                        return code, status, p[6:-4]
        raise RuntimeError(f"no reply to sequence {sequence:#06x}")

    def next_sequence(self):
        self.sequence = (self.sequence + 1) & 0xFFFF
        return self.sequence

    def command(self, code, args=b"", timeout=0.5):
        seq = self.next_sequence()
        packet = seal(bytes([2, 0x10]) + struct.pack("<HB", seq, code) + args)
        got_code, status, payload = self.exchange(packet, seq, timeout)
        assert got_code == code, f"reply names code {got_code:#x}, sent {code:#x}"
        return status, payload


def read_string(payload, at):
    n = payload[at]
    return payload[at + 1:at + 1 + n].decode("utf-8"), at + 1 + n


def identify(board):
    status, p = board.command(0x01)
    assert status == 0, STATUS.get(status)
    info = {"protocol": p[0]}
    at = 1
    for name in ("firmware", "board", "chip", "bus"):
        info[name], at = read_string(p, at)
    (info["sample_rate_hz"], info["decimation"], info["mode"], info["baud"],
     info["calibration_id"], info["calibration_source"], info["stored"]) = \
        struct.unpack_from("<fHBIIBB", p, at)
    at += struct.calcsize("<fHBIIBB")
    names = ("uptime_ms", "frames_sent", "frames_dropped", "overruns",
             "read_failures", "commands", "command_errors", "rx_overflows")
    info.update(zip(names, struct.unpack_from("<8I", p, at)))
    return info


BLOB_LEN = 584


def blob(accel_matrix, accel_bias, gyro_matrix, gyro_bias, cal_id=None):
    """Section 21, version 3: a calibration without temperature terms or G
    (flags 0, G's 72 bytes 0, the id the CRC-32C of bytes 12..=507)."""
    def triad(matrix, bias):
        values = [v for row in matrix for v in row] + list(bias) + [0.0] * 19
        return struct.pack("<31d", *values)
    params = triad(accel_matrix, accel_bias) + triad(gyro_matrix, gyro_bias)
    if cal_id is None:
        cal_id = crc32c(params)
    head = b"TRCL" + bytes([3, 0, 0, 0]) + struct.pack("<I", cal_id)
    body = head + params + bytes(72)
    return body + struct.pack("<I", crc32c(body)), cal_id


def upload(board, data, crc=None):
    """Chunks of 128 bytes in order from 0, then the commit (section 15)."""
    for offset in range(0, len(data), 128):
        status, _ = board.command(0x04, struct.pack("<H", offset) + data[offset:offset + 128])
        if status != 0:
            return status, b""
    if crc is None:
        crc = crc32c(data)
    return board.command(0x05, struct.pack("<HI", len(data), crc))


def read_back(board):
    out, offset = bytearray(), 0
    while True:
        status, p = board.command(0x06, struct.pack("<H", offset))
        assert status == 0, STATUS.get(status)
        total = struct.unpack_from("<H", p)[0]
        out += p[2:]
        offset += len(p) - 2
        if len(p) == 2 or offset >= total:
            return total, bytes(out)


CHECKS = []


def check(name):
    def register(f):
        CHECKS.append((name, f))
        return f
    return register


IDENTITY = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
A_MATRIX = [[1.01, 0.002, 0.0], [0.0, 0.995, -0.001], [0.003, 0.0, 1.004]]


@check("identify: protocol 2, the chip and the counters")
def _(b):
    info = identify(b)
    assert info["protocol"] == 2, info
    assert info["chip"] in ("icm42688", "lsm6dsox"), info
    assert info["stored"] == 1, f"a fresh storage file is empty: {info}"


@check("the stream: data frames, consecutive sequence numbers, rising time")
def _(b):
    b.frames.clear()
    list(b.packets(time.monotonic() + 0.5))
    frames = b.frames
    assert len(frames) >= 20, f"{len(frames)} frames in 0.5 s"
    seqs = [struct.unpack_from("<I", f, 1)[0] for f in frames]
    times = [struct.unpack_from("<I", f, 5)[0] for f in frames]
    gaps = sum(1 for a, c in zip(seqs, seqs[1:]) if (c - a) & 0xFFFFFFFF != 1)
    assert gaps == 0, f"{gaps} gaps"
    assert all(((t1 - t0) & 0xFFFFFFFF) > 0 for t0, t1 in zip(times, times[1:]))


@check("upload: a blob built from section 21 is applied, its id as derived")
def _(b):
    data, cal_id = blob(A_MATRIX, [0.1, -0.2, 0.15], IDENTITY, [0.01, -0.004, 0.002])
    status, p = upload(b, data)
    assert status == 0, (STATUS.get(status), p)
    assert struct.unpack("<I", p)[0] == cal_id
    info = identify(b)
    assert (info["calibration_id"], info["calibration_source"]) == (cal_id, 3), info
    total, back = read_back(b)
    assert (total, back) == (BLOB_LEN, data)
    # Frames now carry the new id (after the change between two samples).
    b.frames.clear()
    list(b.packets(time.monotonic() + 0.3))
    assert struct.unpack_from("<I", b.frames[-1], 15)[0] == cal_id


@check("read calibration at offset = total: ok, no bytes; past it: bad argument")
def _(b):
    status, p = b.command(0x06, struct.pack("<H", BLOB_LEN))
    assert (status, p) == (0, struct.pack("<H", BLOB_LEN)), (status, p)
    status, _ = b.command(0x06, struct.pack("<H", BLOB_LEN + 1))
    assert status == 8, STATUS.get(status)


@check("corrupted uploads are refused and change nothing")
def _(b):
    before = identify(b)["calibration_id"]
    good, _ = blob(A_MATRIX, [0.3, 0.0, 0.0], IDENTITY, [0.0, 0.0, 0.0])
    flipped = bytearray(good)
    flipped[100] ^= 0x10
    cases = [
        ("commit CRC wrong", good, crc32c(good) ^ 1, 1),
        ("blob CRC wrong", bytes(flipped), None, 1),
        ("blob version 4", bytes(good[:4]) + b"\x04" + bytes(good[5:]), None, 2),
        ("not 584 bytes", good[:500], None, None),
    ]
    for name, data, crc, expected in cases:
        if name == "blob version 4":
            body = data[:BLOB_LEN - 4]
            data = body + struct.pack("<I", crc32c(body))
        status, _ = upload(b, data, crc)
        assert status != 0, name
        if expected is not None:
            assert status == expected, (name, STATUS.get(status))
        assert identify(b)["calibration_id"] == before, name
    # A scale of zero: a blob that reads, and a calibration that fails.
    bad, _ = blob([[0.0] * 3] * 3, [0.0] * 3, IDENTITY, [0.0] * 3)
    status, _ = upload(b, bad)
    assert status == 5, STATUS.get(status)
    assert identify(b)["calibration_id"] == before


@check("a retry (same bytes) gets the same reply and is applied once")
def _(b):
    seq = b.next_sequence()
    packet = seal(bytes([2, 0x10]) + struct.pack("<HB", seq, 0x09))  # reset counters
    first = b.exchange(packet, seq)
    # The same bytes again, as after a lost reply: the same reply, counted
    # as a command answered but not applied (a second reset would leave
    # commands at 1 before the identify, 2 with it).
    assert b.exchange(packet, seq) == first == (0x09, 0, b"")
    assert identify(b)["commands"] == 3


@check("reset counters counts itself: the next identify says 2")
def _(b):
    assert b.command(0x09)[0] == 0
    info = identify(b)
    assert (info["commands"], info["command_errors"]) == (2, 0), info


@check("set decimation 0: bad argument; 4: frames four times rarer")
def _(b):
    assert b.command(0x03, struct.pack("<H", 0))[0] == 8
    assert b.command(0x03, struct.pack("<H", 4))[0] == 0
    assert identify(b)["decimation"] == 4
    assert b.command(0x03, struct.pack("<H", 1))[0] == 0


@check("a 240-byte command is read and refused for its arguments' length")
def _(b):
    seq = b.next_sequence()
    args = struct.pack("<H", 0) + bytes([0xAB]) * 229
    packet = seal(bytes([2, 0x10]) + struct.pack("<HB", seq, 0x04) + args)
    assert len(packet) == 240
    code, status, reason = b.exchange(packet, seq)
    assert (code, status) == (0x04, 4), (code, STATUS.get(status), reason)
    assert b"does not fit" not in reason, reason


@check("packets shorter than 5 bytes: malformed, missing bytes read as 0")
def _(b):
    seq = b.next_sequence() & 0xFF
    code, status, _ = b.exchange(bytes([2, 0x10, seq]), seq)
    assert (code, status) == (0, 4), (code, STATUS.get(status))


@check("a later version's packet with a good CRC: wrong version")
def _(b):
    seq = b.next_sequence()
    packet = seal(bytes([3, 0x10]) + struct.pack("<HB", seq, 0x01))
    code, status, _ = b.exchange(packet, seq)
    assert status == 2, STATUS.get(status)


@check("garbage and an oversize packet are answered; the stream is unbroken")
def _(b):
    b.frames.clear()
    seq = b.next_sequence()
    huge = bytes([2, 0x10]) + struct.pack("<HB", seq, 0x01) + bytes([0x55]) * 400
    _, status, _ = b.exchange(huge, seq)
    assert status == 4, STATUS.get(status)
    os.write(b.fd, bytes(range(1, 200)) + b"\x00")
    info = identify(b)
    assert info["protocol"] == 2
    list(b.packets(time.monotonic() + 0.3))
    seqs = [struct.unpack_from("<I", f, 1)[0] for f in b.frames]
    assert all((c - a) & 0xFFFFFFFF == 1 for a, c in zip(seqs, seqs[1:]))


@check("save, then erase: the stored calibration stays in force, flash empty")
def _(b):
    status, p = b.command(0x07, timeout=4.0)
    assert status == 0, (STATUS.get(status), p)
    info = identify(b)
    assert (info["calibration_source"], info["stored"]) == (2, 2), info
    assert b.command(0x08, timeout=4.0)[0] == 0
    info = identify(b)
    assert (info["calibration_source"], info["stored"]) == (2, 1), info


def main():
    board = Board(sys.argv[1])
    failed = 0
    for name, f in CHECKS:
        try:
            f(board)
            print(f"ok    {name}")
        except Exception as e:  # a failed check is reported, the rest still run
            failed += 1
            print(f"FAIL  {name}: {type(e).__name__}: {e}")
    board.close()
    print(f"{len(CHECKS) - failed} of {len(CHECKS)} checks passed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
