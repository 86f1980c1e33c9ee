//! docs/PROTOCOL.md's byte examples, read as the doc tests compare them.

const DOC: &str = include_str!("../../docs/PROTOCOL.md");

/// Hex bytes of the fenced block that follows the line `<!-- name -->`.
pub fn doc_hex(name: &str) -> Vec<u8> {
    let marker = format!("<!-- {name} -->");
    let start = DOC
        .find(&marker)
        .unwrap_or_else(|| panic!("{marker} missing from PROTOCOL.md"));
    let rest = &DOC[start + marker.len()..];
    let open = rest.find("```").expect("fenced block after marker");
    let body_start = open + rest[open..].find('\n').unwrap() + 1;
    let close = body_start + rest[body_start..].find("```").expect("closing fence");
    rest[body_start..close]
        .split_whitespace()
        .map(|t| u8::from_str_radix(t, 16).unwrap_or_else(|_| panic!("bad hex {t:?}")))
        .collect()
}

pub fn hex_lines(bytes: &[u8]) -> String {
    bytes
        .chunks(16)
        .map(|c| {
            c.iter()
                .map(|b| format!("{b:02x}"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect::<Vec<_>>()
        .join("\n")
}
