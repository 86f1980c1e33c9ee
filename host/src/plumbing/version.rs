//! What `triad --version` says: the package version and the versions of the
//! binary formats this build speaks, each defined where the format is (the
//! stream in the core, docs/PROTOCOL.md; the calibration blob in the core's
//! model; the scene blob in the simulator). A decoder that meets a frame of
//! another version rejects it, so the user needs these numbers to know which
//! firmware a `triad` reads.

use std::sync::LazyLock;

/// `0.1.0 (stream protocol v2, calibration blob v3, scene blob v2)`.
pub fn text() -> &'static str {
    static TEXT: LazyLock<String> = LazyLock::new(|| {
        format!(
            "{} (stream protocol v{}, calibration blob v{}, scene blob v{})",
            env!("CARGO_PKG_VERSION"),
            triad::protocol::packet::VERSION,
            triad::model::blob::VERSION,
            triad_sim::scenes::scene_blob::VERSION,
        )
    });
    &TEXT
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_version_names_each_format_version() {
        let text = super::text();
        assert!(text.starts_with(env!("CARGO_PKG_VERSION")), "{text}");
        let stream = format!("stream protocol v{}", triad::protocol::packet::VERSION);
        assert!(text.contains("stream protocol v2"), "{text}");
        assert!(text.contains(&stream), "{text}");
        assert!(text.contains("calibration blob v") && text.contains("scene blob v"));
    }

    #[test]
    fn protocol_md_quotes_the_version_text() {
        let doc = include_str!("../../../docs/PROTOCOL.md")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        let quoted = format!("`triad {}`", super::text());
        assert!(
            doc.contains(&quoted),
            "PROTOCOL.md §9 should quote {quoted}"
        );
    }
}
