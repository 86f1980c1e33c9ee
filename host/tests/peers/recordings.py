"""Independent writers and readers for triad's recording tests (test-only;
run by host/tests/recordings_peers.rs with the venv `cargo xtask test`
prepares: rosbags, pyulog, mcap, mcap-ros2-support).

    recordings.py bags CSV OUTDIR [TOPIC...]   ROS 1 bag and ROS 2 bags (SQLite, MCAP) of the CSV's samples
    recordings.py read-mcap MCAP OUT_CSV       an MCAP's sensor_msgs/msg/Imu (+ Temperature) read back as CSV
    recordings.py ulog ULG OUT_CSV             a ULog's sensor_combined as CSV (pyulog)
"""

import csv
import sys
from pathlib import Path

import numpy as np


def samples(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [
        (float(r["t"]), [float(r[k]) for k in ("ax", "ay", "az")], [float(r[k]) for k in ("gx", "gy", "gz")])
        for r in rows
    ]


def stamp(t):
    ns = round(t * 1e9)
    return ns // 1_000_000_000, ns % 1_000_000_000, ns


def imu_message(types, t, accel, gyro, ros1):
    sec, nsec, _ = stamp(t)
    Time = types["builtin_interfaces/msg/Time"]
    Header = types["std_msgs/msg/Header"]
    Quaternion = types["geometry_msgs/msg/Quaternion"]
    Vector3 = types["geometry_msgs/msg/Vector3"]
    Imu = types["sensor_msgs/msg/Imu"]
    header = Header(seq=0, stamp=Time(sec=sec, nanosec=nsec), frame_id="imu") if ros1 else Header(
        stamp=Time(sec=sec, nanosec=nsec), frame_id="imu"
    )
    return Imu(
        header=header,
        orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.array([-1.0] + [0.0] * 8),
        angular_velocity=Vector3(x=gyro[0], y=gyro[1], z=gyro[2]),
        angular_velocity_covariance=np.zeros(9),
        linear_acceleration=Vector3(x=accel[0], y=accel[1], z=accel[2]),
        linear_acceleration_covariance=np.zeros(9),
    )


def bags(csv_path, out, topics):
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    rows = samples(csv_path)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    topics = topics or ["/imu0"]
    imu = "sensor_msgs/msg/Imu"
    ros1 = get_typestore(Stores.ROS1_NOETIC)
    # Plain chunks, and the two compressions ROS 1 bags use.
    for name, compression in (
        ("ros1.bag", None),
        ("ros1-bz2.bag", Writer1.CompressionFormat.BZ2),
        ("ros1-lz4.bag", Writer1.CompressionFormat.LZ4),
    ):
        w = Writer1(out / name)
        if compression is not None:
            w.set_compression(compression)
        with w:
            conns = [w.add_connection(tp, imu, typestore=ros1) for tp in topics]
            for t, a, g in rows:
                for c in conns:
                    w.write(c, stamp(t)[2], ros1.serialize_ros1(imu_message(ros1.types, t, a, g, True), imu))
    ros2 = get_typestore(Stores.ROS2_HUMBLE)
    for name, plugin in (("ros2_sqlite", StoragePlugin.SQLITE3), ("ros2_mcap", StoragePlugin.MCAP)):
        with Writer2(out / name, version=8, storage_plugin=plugin) as w:
            conns = [w.add_connection(tp, imu, typestore=ros2) for tp in topics]
            for t, a, g in rows:
                for c in conns:
                    w.write(c, stamp(t)[2], ros2.serialize_cdr(imu_message(ros2.types, t, a, g, False), imu))


def read_mcap(path, out):
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    imu, temp, frames = [], {}, {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, msg in reader.iter_decoded_messages():
            t = msg.header.stamp.sec + msg.header.stamp.nanosec / 1e9
            key = (msg.header.stamp.sec, msg.header.stamp.nanosec)
            if schema.name == "sensor_msgs/msg/Imu":
                a, g = msg.linear_acceleration, msg.angular_velocity
                imu.append((key, t, [a.x, a.y, a.z], [g.x, g.y, g.z]))
            elif schema.name == "sensor_msgs/msg/Temperature":
                temp[key] = msg.temperature
            elif schema.name == "triad_msgs/msg/Frame":
                frames[key] = (msg.seq, msg.flags)
    with open(out, "w") as f:
        f.write("t,ax,ay,az,gx,gy,gz" + (",temp" if temp else "") + (",seq,flags" if frames else "") + "\n")
        for key, t, a, g in imu:
            cells = [key[0] * 1_000_000_000 + key[1]] + a + g + ([temp[key]] if temp else [])
            cells += list(frames[key]) if frames else []
            f.write(",".join(repr(c) for c in cells) + "\n")


def ulog(path, out):
    from pyulog import ULog

    d = next(d for d in ULog(str(path), ["sensor_combined"]).data_list if d.multi_id == 0)
    cols = ["accelerometer_m_s2[0]", "accelerometer_m_s2[1]", "accelerometer_m_s2[2]", "gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]"]
    with open(out, "w") as f:
        f.write("t,ax,ay,az,gx,gy,gz\n")
        for k in range(len(d.data["timestamp"])):
            t = int(d.data["timestamp"][k]) / 1e6
            f.write(",".join([repr(t)] + [repr(float(d.data[c][k])) for c in cols]) + "\n")


if __name__ == "__main__":
    verb, args = sys.argv[1], sys.argv[2:]
    {"bags": lambda: bags(args[0], args[1], args[2:]), "read-mcap": lambda: read_mcap(*args), "ulog": lambda: ulog(*args)}[verb]()
