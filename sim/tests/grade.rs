//! The grade tables are THEORY.md's, every preset lies inside its grade's
//! row (and in no better grade's, for the error parameters), and a preset's
//! SI effects are its data-sheet numbers converted.

use triad::units::{
    arw_deg_per_sqrt_h_to_si, deg_per_h_to_rad_per_s, ppm_to_ratio, ug_per_sqrt_hz_to_si,
    ug_to_mps2,
};
use triad_sim::grade::{
    AccelGrade, AccelPreset, Cell, Grade, GyroGrade, GyroPreset, Optics, Parameter, Table,
    Technology, ACCEL_TABLE, FOG_FIGURES, GYRO_TABLE, RLG_FIGURES,
};

/// The tables as THEORY.md prints them, cell by cell (its own text, with
/// the accelerometer rows in one unit each: see the module comment of
/// `triad_sim::grade::table`).
#[test]
fn the_tables_print_as_theory_writes_them() {
    let row = |t: &Table, p| -> Vec<String> {
        t.row(p)
            .unwrap()
            .cells
            .iter()
            .map(|c| c.to_string())
            .collect()
    };
    assert_eq!(
        row(&GYRO_TABLE, Parameter::Noise),
        ["> 0.5", "0.05–0.5", "< 0.05", "< 0.001"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::BiasInstability),
        ["> 10", "1–10", "< 0.1", "< 0.01"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::ScaleFactorInstability),
        ["0.1–1", "0.01–0.1", "< 0.01", "< 0.001"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::Range),
        ["50–1000", "> 500", "50–300", "> 400"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::Bandwidth),
        ["> 70", "≈ 500", "≈ 100", "100–500"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::Shock),
        ["1000", "1000–10000", "1000", "1000"]
    );
    assert_eq!(
        row(&GYRO_TABLE, Parameter::Cost),
        ["500–5000", "5000–20000", "20000–50000", "50000–100000"]
    );
    assert_eq!(
        GYRO_TABLE.technology.unwrap(),
        ["MEMS", "MEMS, FOG", "RLG, FOG", "RLG, FOG?"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::Noise),
        ["stability control 500; airbag 5000", "50–500", "< 10"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::BiasInstability),
        ["10000–100000", "200–1000", "10–100"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::ScaleFactorInstability),
        ["> 10000", "100–1000", "< 100"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::Range),
        ["stability control 2; airbag 50", "> 50", "2–50"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::Bandwidth),
        ["0–400", "50–300", "50–300"]
    );
    assert_eq!(
        row(&ACCEL_TABLE, Parameter::Shock),
        ["> 2000", "< 200", "> 10"]
    );
    assert!(ACCEL_TABLE.row(Parameter::Cost).is_none() && ACCEL_TABLE.technology.is_none());
    for t in [&GYRO_TABLE, &ACCEL_TABLE] {
        for r in t.rows {
            assert_eq!(
                r.cells.len(),
                t.grades.len(),
                "{} {:?}",
                t.name,
                r.parameter
            );
        }
    }
}

#[test]
fn cells_hold_what_their_text_says() {
    assert!(Cell::Above(0.5).holds(0.51) && !Cell::Above(0.5).holds(0.5));
    assert!(Cell::Below(0.05).holds(0.0) && !Cell::Below(0.05).holds(0.05));
    assert!(Cell::Range(1.0, 10.0).holds(1.0) && Cell::Range(1.0, 10.0).holds(10.0));
    assert!(!Cell::Range(1.0, 10.0).holds(0.99));
    // "≈ 500" is 250–1000; "10³" likewise a factor of two either way.
    assert!(Cell::About(500.0).holds(260.0) && !Cell::About(500.0).holds(1100.0));
    assert!(Cell::Order(1e3).holds(1500.0));
    let uses = Cell::Uses(&[("a", 2.0), ("b", 50.0)]);
    assert!(uses.holds(2.0) && uses.holds(20.0) && !uses.holds(60.0));
    assert!(Cell::Range(1.0, 10.0).above(0.5) && Cell::Below(0.1).below(0.5));
    assert!(Cell::Above(10.0).above(10.0) && !Cell::Above(10.0).below(11.0));
}

/// Every cell of `preset`'s grade holds the preset's value.
fn assert_in_row(table: &Table, grade: usize, name: &str, values: &[(Parameter, f64)]) {
    for &(p, v) in values {
        let cell = table.cell(p, grade).unwrap();
        assert!(
            cell.holds(v),
            "{name}: {} {v} not in {} row {cell}",
            p.name(),
            table.grades[grade]
        );
        // An error parameter is in no better grade's cell: the preset is
        // not a better sensor than its grade.
        if p.ranks() {
            for better in grade + 1..table.grades.len() {
                let c = table.cell(p, better).unwrap();
                assert!(!c.holds(v), "{name}: {} {v} also in {c}", p.name());
            }
        }
    }
}

#[test]
fn each_preset_lies_inside_its_row() {
    for p in &GyroPreset::ALL {
        assert_in_row(&GYRO_TABLE, p.grade.index(), p.name, &p.values());
    }
    for p in &AccelPreset::ALL {
        assert_in_row(&ACCEL_TABLE, p.grade.index(), p.name, &p.values());
    }
    // Every grade has a preset.
    for g in GyroGrade::ALL {
        assert!(GyroPreset::ALL.iter().any(|p| p.grade == g), "{g:?}");
    }
    for g in AccelGrade::ALL {
        assert!(AccelPreset::ALL.iter().any(|p| p.grade == g), "{g:?}");
    }
}

#[test]
fn preset_effects_are_the_converted_numbers() {
    for p in &GyroPreset::ALL {
        let e = p.effects();
        let white = (p.technology != Technology::RingLaser)
            .then_some([arw_deg_per_sqrt_h_to_si(p.arw_deg_per_sqrt_h); 3]);
        assert_eq!(e.white_noise, white, "{}", p.name);
        let bi = e.bias_instability.unwrap();
        assert!(bi
            .iter()
            .all(|b| b.b == deg_per_h_to_rad_per_s(p.bias_instability_deg_per_h)));
        let sf = p.scale_factor_instability_percent / 100.0;
        assert_eq!(e.turn_on_scale, Some([sf; 3]));
        assert_eq!(GyroPreset::named(p.name), Some(p));
    }
    for p in &AccelPreset::ALL {
        let e = p.effects();
        assert_eq!(
            e.white_noise,
            Some([ug_per_sqrt_hz_to_si(p.noise_ug_per_sqrt_hz); 3])
        );
        let bi = e.bias_instability.unwrap();
        assert!(bi.iter().all(|b| b.b == ug_to_mps2(p.bias_instability_ug)));
        let sf = ppm_to_ratio(p.scale_factor_instability_ppm);
        assert_eq!(e.turn_on_scale, Some([sf; 3]));
        assert_eq!(AccelPreset::named(p.name), Some(p));
    }
    assert_eq!(GyroPreset::named("strategic"), None);
    assert_eq!(GyroGrade::RateGrade.name(), "rate grade");
    assert_eq!(AccelGrade::Automotive.name(), "automotive");
}

#[test]
fn each_technology_is_one_the_table_pairs_with_its_grade() {
    // THEORY.md's headings: rate grade (MEMS), tactical (MEMS, FOG),
    // aviation (RLG, FOG), navigation (RLG, FOG?).
    let technologies = GYRO_TABLE.technology.unwrap();
    for p in &GyroPreset::ALL {
        let paired = technologies[p.grade.index()];
        match p.technology {
            Technology::NoiseTerms => {}
            t => assert!(
                paired.contains(t.name()),
                "{}: {} not in \"{paired}\"",
                p.name,
                t.name()
            ),
        }
    }
    let named = |n: &str| GyroPreset::named(n).unwrap().technology;
    assert_eq!(named("tactical-fog"), Technology::FibreOptic);
    assert_eq!(named("aviation-rlg"), Technology::RingLaser);
    assert_eq!(named("aviation-fog"), Technology::FibreOptic);
    assert_eq!(named("navigation-rlg"), Technology::RingLaser);
}

#[test]
fn optical_presets_have_their_technologys_figures() {
    for p in &GyroPreset::ALL {
        let (figures, optics) = match p.optics {
            Some(o @ Optics::RingLaser(_)) => (RLG_FIGURES, o),
            Some(o @ Optics::FibreOptic(_)) => (FOG_FIGURES, o),
            None => continue,
        };
        assert!(
            figures.bias_deg_per_h.holds(p.bias_deg_per_h),
            "{} bias",
            p.name
        );
        assert!(
            figures
                .scale_factor_error_ppm
                .holds(p.scale_factor_error_ppm),
            "{} scale-factor error",
            p.name
        );
        let e = p.effects();
        let s = e.scale_misalignment.unwrap();
        assert_eq!(s[1][1], ppm_to_ratio(p.scale_factor_error_ppm));
        assert_eq!(
            e.constant_bias,
            Some([deg_per_h_to_rad_per_s(p.bias_deg_per_h); 3])
        );
        match optics {
            Optics::RingLaser(r) => {
                let arcsec = r.fringe_angle().to_degrees() * 3600.0;
                assert!(
                    figures.fringe_arcsec.unwrap().holds(arcsec),
                    "{}: {arcsec}",
                    p.name
                );
                // The preset's ARW is its dither's walk (stated to 1 %).
                let walk = r.dither_random_walk().to_degrees() * 60.0;
                assert!(
                    (p.arw_deg_per_sqrt_h / walk - 1.0).abs() < 0.01,
                    "{}: {walk}",
                    p.name
                );
                assert_eq!(e.ring_laser, Some(r));
            }
            Optics::FibreOptic(f) => assert_eq!(e.fibre_optic, Some(f)),
        }
    }
}

/// A preset's row of scenes/README.md: each value with its grade's cell.
fn readme_row(
    name: &str,
    grade: &str,
    technology: &str,
    table: &Table,
    g: usize,
    values: &[(Parameter, f64)],
) -> String {
    let cells: Vec<String> = values
        .iter()
        .map(|&(p, v)| format!("{v} ({})", table.cell(p, g).unwrap()))
        .collect();
    format!(
        "| `{name}` | {grade} | {technology} | {} |",
        cells.join(" | ")
    )
}

#[test]
fn scenes_readme_lists_every_preset_with_its_values_and_row() {
    let readme = include_str!("../../scenes/README.md");
    let mut rows = Vec::new();
    for p in &GyroPreset::ALL {
        let g = p.grade.index();
        let tech = p.technology.name();
        rows.push(readme_row(
            p.name,
            p.grade.name(),
            tech,
            &GYRO_TABLE,
            g,
            &p.values(),
        ));
    }
    for p in &AccelPreset::ALL {
        let g = p.grade.index();
        rows.push(readme_row(
            p.name,
            p.grade.name(),
            "—",
            &ACCEL_TABLE,
            g,
            &p.values(),
        ));
    }
    let missing: Vec<&String> = rows
        .iter()
        .filter(|r| !readme.contains(r.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "scenes/README.md lacks these rows:\n{}",
        missing
            .iter()
            .map(|r| r.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}
