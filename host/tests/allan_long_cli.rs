//! `triad allan` on a record long enough for its strided octaves (m above
//! `triad_lab::allan::strided::BASE` = 2^17): every octave up to the base
//! is the fully overlapping estimate of the record held in memory, those
//! above are the overlapping estimate with terms every m/2^17 samples, each
//! to 1e-9 relative, whatever thread integrated the column.

mod common;

use std::io::Write;

use common::{allan, s, text, tmp};
use triad_lab::allan::direct;
use triad_lab::allan::strided::{stride, BASE};
use triad_sim::effects::rng::Rng;

/// Samples: 2^19 + 4000, so octaves m = 2^18 (stride 2) has terms and
/// m = 2^19 none.
const SAMPLES: usize = (1 << 19) + 4000;

/// Three columns of different character: white noise, white noise on a
/// 1 g mean, white noise plus a random walk.
fn record() -> [Vec<f64>; 3] {
    let mut rng = Rng::from_seed(24);
    let mut cols: [Vec<f64>; 3] = Default::default();
    let mut walk = 0.0;
    for _ in 0..SAMPLES {
        walk += 1e-5 * rng.gaussian();
        cols[0].push(1e-3 * rng.gaussian());
        cols[1].push(9.806_65 + 2e-3 * rng.gaussian());
        cols[2].push(1e-3 * rng.gaussian() + walk);
    }
    cols
}

#[test]
fn long_octaves_are_the_in_memory_ones_or_the_strided_definition() {
    let cols = record();
    let input = tmp("long.csv");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&input).unwrap());
    writeln!(w, "t,gx,ay,gz").unwrap();
    for (i, ((a, b), c)) in cols[0].iter().zip(&cols[1]).zip(&cols[2]).enumerate() {
        // Shortest round-trip formatting: the file holds these very values.
        writeln!(w, "{},{a},{b},{c}", i as f64 * 0.01).unwrap();
    }
    w.flush().unwrap();
    drop(w);
    let table = tmp("long-table.csv");
    let o = allan(&input, &["--rate", "100", "--json", "--out", s(&table)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = std::fs::read_to_string(&table).unwrap();
    for (c, name) in ["gx", "ay", "gz"].into_iter().enumerate() {
        let y = &cols[c];
        // The offset triad subtracts (the mean of the first 4096 rows).
        let offset = y[..4096].iter().sum::<f64>() / 4096.0;
        let mut sums = vec![0.0; y.len() + 1];
        direct::cumulative_sums(y, offset, &mut sums);
        let mine: Vec<Vec<&str>> = rows
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[0] == name)
            .collect();
        assert_eq!(mine.len(), 19, "{name}: octaves 1 … 2^18");
        let curve = json["columns"][c]["curve"].as_array().unwrap();
        for (k, f) in mine.iter().enumerate() {
            let m: usize = f[5].parse().unwrap();
            assert_eq!(m, 1 << k);
            let oadev: f64 = f[2].parse().unwrap();
            let terms: u64 = f[6].parse().unwrap();
            let d = stride(m as u64, BASE) as usize;
            // Every d-th term from k = 2m: the in-memory estimator's stride d.
            let (want, want_terms) = direct::allan_variance(&sums, m, d).unwrap();
            assert_eq!(terms, want_terms, "{name} m = {m}");
            assert!(
                (oadev - want.sqrt()).abs() <= 1e-9 * want.sqrt(),
                "{name} m = {m}: {oadev} against {}",
                want.sqrt()
            );
            assert_eq!(curve[k]["stride"].as_u64(), Some(d as u64));
        }
        // The top octave is strided (every 2nd term) and has a fit behind it.
        assert_eq!(curve[18]["stride"].as_u64(), Some(2));
        assert!(
            json["columns"][c]["fit"].is_object(),
            "{name}: {}",
            json["columns"][c]["no_fit"]
        );
    }
}
