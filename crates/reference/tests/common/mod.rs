//! The paper case of MODEL.md section 4, built in code (independent of the scene parser).
#![allow(dead_code)]

use clutchpack_model::*;

pub fn paper_law(kind: LawKind, h_o: f64) -> ToothLaw {
    ToothLaw {
        kind,
        hertz: Hertz {
            modulus_pa: 210e9,
            curvature_radius_m: 1.75e-3,
            loss_coefficient_s_m: 0.8,
        },
        oil: OilFilm {
            thickness_m: h_o,
            viscosity_pa_s: 289.1,
            leakage_coefficient: 0.421,
            width_m: 3e-3,
            length_m: 3e-3,
            v_floor_m_s: 0.01,
            h_min_m: 1e-6,
        },
    }
}

pub fn paper_spline() -> SplineGeometry {
    SplineGeometry {
        teeth: 154,
        pitch_radius_m: 0.231,
        pressure_angle_rad: 20f64.to_radians(),
        backlash_m: 0.75e-3,
    }
}

pub fn paper_disc(h_o: f64) -> DiscModel {
    DiscModel {
        name: "disc".into(),
        spline: paper_spline(),
        law: paper_law(LawKind::Paper, h_o),
        inertia_kg_m2: 0.156,
        drag_n_m_s_rad: 0.01,
        initial_rel_angle_rad: 0.0,
        initial_rel_speed_rad_s: 0.0,
        radial_float: false,
        tooth_spacing_errors_m: Vec::new(),
        initial_offset_m: [0.0, 0.0],
    }
}

pub fn paper_pack(h_o: f64) -> PackModel {
    PackModel {
        shaft: Shaft::Prescribed(SpeedProfile::sine(200.0, 4.378, 104.0)),
        discs: vec![paper_disc(h_o)],
        plates: Vec::new(),
        drum: None,
        stack: None,
    }
}
