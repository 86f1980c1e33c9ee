//! Grade presets lie inside their published table rows, and their SI effects
//! are the preset's data-sheet numbers converted.

use triad::units::{
    arw_deg_per_sqrt_h_to_si, deg_per_h_to_rad_per_s, ppm_to_ratio, ug_per_sqrt_hz_to_si,
    ug_to_mps2,
};
use triad_sim::grade::{AccelGrade, GyroGrade};

#[test]
fn each_gyro_preset_lies_inside_its_table_row() {
    for g in GyroGrade::ALL {
        let (p, row) = (g.preset(), g.row());
        assert!(
            row.arw_deg_per_sqrt_h.contains(p.arw_deg_per_sqrt_h),
            "{g:?} ARW"
        );
        assert!(
            row.bias_instability_deg_per_h
                .contains(p.bias_instability_deg_per_h),
            "{g:?} bias instability"
        );
        assert!(
            row.scale_factor_ppm.contains(p.scale_factor_ppm),
            "{g:?} scale factor"
        );
    }
}

#[test]
fn each_accel_preset_lies_inside_its_table_row() {
    for g in AccelGrade::ALL {
        let (p, row) = (g.preset(), g.row());
        assert!(
            row.noise_ug_per_sqrt_hz.contains(p.noise_ug_per_sqrt_hz),
            "{g:?} noise"
        );
        assert!(
            row.bias_instability_ug.contains(p.bias_instability_ug),
            "{g:?} bias instability"
        );
        assert!(
            row.scale_factor_ppm.contains(p.scale_factor_ppm),
            "{g:?} scale factor"
        );
    }
}

#[test]
fn better_grades_have_lower_preset_errors() {
    // The presets are ordered as the grades are: each step up the table
    // lowers every error.
    for w in GyroGrade::ALL.windows(2) {
        let (a, b) = (w[0].preset(), w[1].preset());
        assert!(b.arw_deg_per_sqrt_h < a.arw_deg_per_sqrt_h);
        assert!(b.bias_instability_deg_per_h < a.bias_instability_deg_per_h);
        assert!(b.scale_factor_ppm < a.scale_factor_ppm);
    }
    for w in AccelGrade::ALL.windows(2) {
        let (a, b) = (w[0].preset(), w[1].preset());
        assert!(b.noise_ug_per_sqrt_hz < a.noise_ug_per_sqrt_hz);
        assert!(b.bias_instability_ug < a.bias_instability_ug);
        assert!(b.scale_factor_ppm < a.scale_factor_ppm);
    }
}

#[test]
fn preset_effects_are_the_converted_numbers() {
    for g in GyroGrade::ALL {
        let (p, e) = (g.preset(), g.effects());
        assert_eq!(
            e.white_noise,
            Some([arw_deg_per_sqrt_h_to_si(p.arw_deg_per_sqrt_h); 3])
        );
        let bi = e.bias_instability.unwrap();
        assert!(bi
            .iter()
            .all(|b| b.b == deg_per_h_to_rad_per_s(p.bias_instability_deg_per_h)));
        assert_eq!(e.turn_on_scale, Some([ppm_to_ratio(p.scale_factor_ppm); 3]));
        assert_eq!(GyroGrade::from_name(g.name()), Some(g));
    }
    for g in AccelGrade::ALL {
        let (p, e) = (g.preset(), g.effects());
        assert_eq!(
            e.white_noise,
            Some([ug_per_sqrt_hz_to_si(p.noise_ug_per_sqrt_hz); 3])
        );
        let bi = e.bias_instability.unwrap();
        assert!(bi.iter().all(|b| b.b == ug_to_mps2(p.bias_instability_ug)));
        assert_eq!(AccelGrade::from_name(g.name()), Some(g));
    }
    assert_eq!(GyroGrade::from_name("strategic"), None);
}
