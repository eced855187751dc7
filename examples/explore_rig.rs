//! Where in the space of rigs do the paper's couplings appear? Random rigs (thin plate
//! clamped across x or across y, its span, thick plate, pin height, pad shear modulus; the
//! thin plate's thickness set by the span for about 1.6 MN/m), each swept in mu through
//! `cms` on a coarse rule, print their couplings as JSON lines. This is how the starting
//! point of `examples/calibrate/rig.toml` was found: the rigs with both couplings had the
//! plate clamped at its radial ends.
//!
//! ```text
//! cargo run --release --example explore_rig -- [COUNT] [SEED] > rigs.jsonl
//! ```

use squeal::analysis::mu_sweep::{mu_list, run_sweep, MuSweepSettings};
use squeal::analysis::pipeline::Prepared;
use squeal::scene::{Clamp, Scene};

/// xorshift64, uniform in [0, 1).
fn uniform(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).map_or(Ok(20), |a| a.parse())?;
    let mut state: u64 = args.get(2).map_or(Ok(7), |a| a.parse())?.max(1);
    let reg = squeal::registry();
    let base = Scene::builtin("pin-on-disc")?;
    for i in 0..count {
        let log = |s: &mut u64, a: f64, b: f64| (a.ln() + uniform(s) * (b / a).ln()).exp();
        let clamp = if uniform(&mut state) < 0.5 {
            Clamp::X
        } else {
            Clamp::Y
        };
        let span = 0.09 + 0.07 * uniform(&mut state);
        let thick = log(&mut state, 0.003, 0.012);
        let height = 0.005 + 0.013 * uniform(&mut state);
        let g = log(&mut state, 1e9, 8e9);
        // two guided-clamped spans of (span - 40 mm) / 2 in series with the disc: about
        // 1.6 MN/m for a thickness of 7.07 % of one span (60 GPa plate, 40 mm wide)
        let thin = 0.07066 * (span - 0.04) / 2.0;
        let mut scene = base.with_values(
            &[
                ("thin_plate.thickness_m", thin),
                ("thick_plate.thickness_m", thick),
                ("pin.height_m", height),
                ("pin.material.shear_modulus_axial_pa", g),
                ("mesh.elements_per_wavelength", 8.0),
                ("mesh.plate_elements_per_wavelength", 12.0),
                ("mesh.min_layers", 2.0),
                ("mesh.pin_face_elements", 10.0),
            ],
            "explore",
        )?;
        let plate = scene
            .thin_plate
            .as_mut()
            .expect("the default rig has a thin plate");
        plate.clamp = Some(clamp);
        let (along, across) = (span, 0.040);
        (plate.length_x_m, plate.width_y_m) = match clamp {
            Clamp::Y => (across, along),
            _ => (along, across),
        };
        let prep = Prepared::new(&reg, scene, "explore")?;
        let settings = MuSweepSettings::new(mu_list(0.1, 0.8, 0.05)?, "cms", [0.0, 5000.0]);
        let sweep = run_sweep(&reg, &prep, &settings, None, |_| {})?;
        let couplings: Vec<_> = sweep
            .couplings
            .iter()
            .map(|c| {
                serde_json::json!({
                    "freq_hz": c.freq_hz.round(), "mu": [c.mu_from, c.mu_to],
                    "max_dvr": c.max_dvr, "made_of": c.free_interface_mac.first(),
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "rig": i, "clamp": format!("{clamp:?}"), "span_m": span, "thin_m": thin,
                "thick_m": thick, "pin_height_m": height, "shear_modulus_pa": g,
                "couplings": couplings,
            })
        );
    }
    Ok(())
}
