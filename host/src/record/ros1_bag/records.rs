//! ROS bag 2.0's record framing (wiki.ros.org/Bags/Format/2.0, "Records"):
//! every record is `header_len u32 | header | data_len u32 | data`, a
//! header a run of `field_len u32 | name=value` fields, little-endian. The
//! same framing holds in the file and inside a decompressed chunk, so one
//! reader serves both, over any `Read` whose length is known: a length that
//! points past the end is an error before anything is allocated.

use std::io::Read;

/// One record: where it starts, its header and its data.
#[derive(Default)]
pub struct Record {
    /// Byte offset of the record in its file (or chunk).
    pub offset: u64,
    /// The header's fields, as written.
    pub header: Vec<u8>,
    /// The data.
    pub data: Vec<u8>,
}

impl Record {
    /// The `op` field: which kind of record this is.
    pub fn op(&self) -> Result<u8, String> {
        match field(&self.header, "op")? {
            Some([op]) => Ok(*op),
            Some(v) => Err(format!("its op field has {} bytes, not 1", v.len())),
            None => Err("its header has no op field".into()),
        }
    }
}

/// The value of field `name` in `fields` (a record's header, or a connection
/// record's data), if it is there.
pub fn field<'a>(mut fields: &'a [u8], name: &str) -> Result<Option<&'a [u8]>, String> {
    while !fields.is_empty() {
        let len = u32_at(fields, 0).ok_or("a header field's length is cut off")? as usize;
        let body = fields
            .get(4..4 + len)
            .ok_or_else(|| format!("a header field of {len} bytes runs past its header"))?;
        let eq = body
            .iter()
            .position(|&b| b == b'=')
            .ok_or("a header field has no `=`")?;
        if &body[..eq] == name.as_bytes() {
            return Ok(Some(&body[eq + 1..]));
        }
        fields = &fields[4 + len..];
    }
    Ok(None)
}

/// Field `name`'s `N` bytes, required.
fn fixed_field<const N: usize>(fields: &[u8], name: &str) -> Result<[u8; N], String> {
    let v = field(fields, name)?.ok_or_else(|| format!("it has no {name} field"))?;
    v.try_into()
        .map_err(|_| format!("its {name} field has {} bytes, not {N}", v.len()))
}

/// Field `name` as a little-endian u32, required.
pub fn u32_field(fields: &[u8], name: &str) -> Result<u32, String> {
    fixed_field(fields, name).map(u32::from_le_bytes)
}

/// Field `name` as a little-endian u64, required.
pub fn u64_field(fields: &[u8], name: &str) -> Result<u64, String> {
    fixed_field(fields, name).map(u64::from_le_bytes)
}

/// Field `name` as ROS time (u32 seconds, u32 nanoseconds), in nanoseconds.
pub fn time_field(fields: &[u8], name: &str) -> Result<u64, String> {
    let v = u64_field(fields, name)?;
    Ok(u64::from(v as u32) * 1_000_000_000 + (v >> 32))
}

/// Field `name` as text, required.
pub fn text_field<'a>(fields: &'a [u8], name: &str) -> Result<&'a str, String> {
    let v = field(fields, name)?.ok_or_else(|| format!("it has no {name} field"))?;
    std::str::from_utf8(v).map_err(|_| format!("its {name} field is not UTF-8"))
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    bytes
        .get(at..at + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Records read one after another from `inner`, which holds bytes
/// `pos..end` of a file (or chunk).
pub struct Records<R> {
    inner: R,
    pos: u64,
    end: u64,
}

impl<R: Read> Records<R> {
    /// Records from `inner`, positioned at byte `pos` of a whole `end` bytes long.
    pub fn new(inner: R, pos: u64, end: u64) -> Records<R> {
        Records { inner, pos, end }
    }

    /// Reads the next record into `record` (its buffers reused); false at `end`.
    pub fn next_into(&mut self, record: &mut Record) -> Result<bool, String> {
        if self.pos >= self.end {
            return Ok(false);
        }
        record.offset = self.pos;
        self.part(&mut record.header, "header")?;
        self.part(&mut record.data, "data")?;
        Ok(true)
    }

    /// A length-prefixed part of a record into `buf`.
    fn part(&mut self, buf: &mut Vec<u8>, what: &str) -> Result<(), String> {
        let mut len = [0u8; 4];
        self.read(&mut len)
            .map_err(|e| format!("the {what}'s length is cut off ({e})"))?;
        let len = u32::from_le_bytes(len) as u64;
        let left = self.end - self.pos;
        if len > left {
            return Err(format!(
                "its {what} of {len} bytes runs past the end ({left} bytes left)"
            ));
        }
        buf.clear();
        buf.resize(len as usize, 0);
        self.read(buf)
            .map_err(|e| format!("its {what} is cut off ({e})"))
    }

    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<()> {
        if (buf.len() as u64) > self.end - self.pos {
            return Err(std::io::ErrorKind::UnexpectedEof.into());
        }
        self.inner.read_exact(buf)?;
        self.pos += buf.len() as u64;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn put_field(out: &mut Vec<u8>, name: &str, value: &[u8]) {
        out.extend(((name.len() + 1 + value.len()) as u32).to_le_bytes());
        out.extend(name.as_bytes());
        out.push(b'=');
        out.extend(value);
    }

    fn put_record(out: &mut Vec<u8>, header: &[u8], data: &[u8]) {
        out.extend((header.len() as u32).to_le_bytes());
        out.extend(header);
        out.extend((data.len() as u32).to_le_bytes());
        out.extend(data);
    }

    #[test]
    fn records_and_fields_read_back() {
        let mut header = Vec::new();
        put_field(&mut header, "op", &[2]);
        put_field(&mut header, "conn", &7u32.to_le_bytes());
        put_field(&mut header, "time", &((5u64 << 32) | 3).to_le_bytes());
        let mut bytes = Vec::new();
        put_record(&mut bytes, &header, b"abc");
        put_record(&mut bytes, &header, b"");
        let mut records = Records::new(&bytes[..], 0, bytes.len() as u64);
        let mut r = Record::default();
        assert!(records.next_into(&mut r).unwrap());
        assert_eq!(
            (r.offset, r.op().unwrap(), &r.data[..]),
            (0, 2, &b"abc"[..])
        );
        assert_eq!(u32_field(&r.header, "conn").unwrap(), 7);
        assert_eq!(time_field(&r.header, "time").unwrap(), 3_000_000_005);
        assert!(field(&r.header, "topic").unwrap().is_none());
        assert!(records.next_into(&mut r).unwrap());
        assert!(r.data.is_empty());
        assert!(!records.next_into(&mut r).unwrap());
    }

    #[test]
    fn a_length_past_the_end_is_an_error_before_any_allocation() {
        let mut bytes = Vec::new();
        bytes.extend(u32::MAX.to_le_bytes());
        bytes.extend([0u8; 8]);
        let mut records = Records::new(&bytes[..], 0, bytes.len() as u64);
        let e = records.next_into(&mut Record::default()).unwrap_err();
        assert_eq!(
            e,
            "its header of 4294967295 bytes runs past the end (8 bytes left)"
        );
        let mut header = Vec::new();
        put_field(&mut header, "op", &[2]);
        header.truncate(header.len() - 1);
        assert_eq!(
            field(&header, "op").unwrap_err(),
            "a header field of 4 bytes runs past its header"
        );
    }
}
