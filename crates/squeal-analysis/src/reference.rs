//! Reference values of the source paper ("Multi-Scale Contact Localization and Dynamic
//! Instability Related to Brake Squeal"), read from one committed data file,
//! `crates/squeal-analysis/data/paper.toml`, which says where each number comes from.
//! Every comparison with the paper (validate, calibration specs, studies) takes its
//! numbers from here.

use serde::Deserialize;
use std::sync::OnceLock;

/// The data file, embedded.
pub const PAPER_TOML: &str = include_str!("../data/paper.toml");

/// One of the paper's uniform-contact couplings (section 2.3).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PaperCoupling {
    /// `coupling 1`, `coupling 2`.
    pub name: String,
    /// Unstable frequency (Hz).
    pub freq_hz: f64,
    /// Friction coefficients where the mode is unstable.
    pub mu_range: [f64; 2],
    /// The partners as the paper names them.
    pub partners: String,
}

/// One Table 2 row: label, frequency (Hz), whether a doublet.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct DiscMode {
    /// `a,0,3`, `c,1`, ...
    pub label: String,
    /// The paper's FE frequency (Hz).
    pub freq_hz: f64,
    /// A pair of equal frequencies.
    pub double: bool,
}

/// One of the mesoscopic plateau studies (section 3.2).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PaperMeso {
    /// The patch sides (m).
    pub patch_sizes_m: Vec<f64>,
    /// Unstable fraction of the 1400 layouts.
    pub unstable_fraction: f64,
    /// Range of the divergence rates of the unstable layouts.
    pub dvr_range: [f64; 2],
    /// Unstable frequency (Hz).
    pub freq_hz: f64,
}

/// What squeal reads of the data file.
#[derive(Debug, Clone, PartialEq)]
pub struct Paper {
    /// Table 2: the disc's modes with a free contact face.
    pub disc_modes: Vec<DiscMode>,
    /// Pin assembly modes below 10 kHz.
    pub pin_modes_below_10khz: usize,
    /// Imposed axial displacement of the disc's clamped face (m) ...
    pub load_displacement_m: f64,
    /// ... and the normal force it gives (N).
    pub load_force_n: f64,
    /// The uniform-contact couplings.
    pub couplings: Vec<PaperCoupling>,
    /// Friction coefficients of the macroscopic study.
    pub macro_mu: Vec<f64>,
    /// Width `b` of the centred a-sweep of the macroscopic study (m).
    pub macro_b_m: f64,
    /// Friction coefficient of the mesoscopic studies.
    pub meso_mu: f64,
    /// Layouts per patch size.
    pub meso_layouts: usize,
    /// Contact grid of the coupling-2 study (m).
    pub meso_element_m: f64,
    /// The coupling-2 (2100 Hz) plateau study.
    pub meso_coupling_2: PaperMeso,
    /// The coupling-1 (3500 Hz) plateau study.
    pub meso_coupling_1: PaperMeso,
}

impl Paper {
    /// The rig's axial stiffness the paper's load datum gives (N/m): 200 N / 125 um.
    pub fn rig_stiffness_n_per_m(&self) -> f64 {
        self.load_force_n / self.load_displacement_m
    }

    /// The coupling near `freq_hz` (within 15 %).
    pub fn coupling_near(&self, freq_hz: f64) -> Option<&PaperCoupling> {
        self.couplings
            .iter()
            .find(|c| (c.freq_hz - freq_hz).abs() < 0.15 * c.freq_hz)
    }
}

#[derive(Deserialize)]
struct File {
    model: Model,
    disc_modes: Vec<DiscMode>,
    pin_modes: PinModes,
    uniform_contact: Uniform,
    macroscopic: Macroscopic,
    mesoscopic: Mesoscopic,
}

#[derive(Deserialize)]
struct Model {
    load_imposed_disc_displacement_m: f64,
    load_resulting_normal_force_n: f64,
}

#[derive(Deserialize)]
struct PinModes {
    count_below_10khz: usize,
}

#[derive(Deserialize)]
struct Uniform {
    couplings: Vec<PaperCoupling>,
}

#[derive(Deserialize)]
struct Macroscopic {
    mu: Vec<f64>,
    centred_a_sweep_b_m: f64,
}

#[derive(Deserialize)]
struct Mesoscopic {
    mu: f64,
    distributions_per_patch_size: usize,
    contact_mesh_element_m: f64,
    coupling_2: PaperMeso,
    coupling_1: PaperMeso,
}

/// The paper's numbers (parsed once).
pub fn paper() -> &'static Paper {
    static PAPER: OnceLock<Paper> = OnceLock::new();
    PAPER.get_or_init(|| {
        let f: File =
            toml::from_str(PAPER_TOML).expect("data/paper.toml is valid (a test reads it)");
        Paper {
            disc_modes: f.disc_modes,
            pin_modes_below_10khz: f.pin_modes.count_below_10khz,
            load_displacement_m: f.model.load_imposed_disc_displacement_m,
            load_force_n: f.model.load_resulting_normal_force_n,
            couplings: f.uniform_contact.couplings,
            macro_mu: f.macroscopic.mu,
            macro_b_m: f.macroscopic.centred_a_sweep_b_m,
            meso_mu: f.mesoscopic.mu,
            meso_layouts: f.mesoscopic.distributions_per_patch_size,
            meso_element_m: f.mesoscopic.contact_mesh_element_m,
            meso_coupling_2: f.mesoscopic.coupling_2,
            meso_coupling_1: f.mesoscopic.coupling_1,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_file_reads_and_holds_the_papers_numbers() {
        let p = paper();
        assert_eq!(p.disc_modes.len(), 16);
        assert_eq!(p.disc_modes[3].label, "a,0,3");
        assert_eq!(p.pin_modes_below_10khz, 6);
        assert!((p.rig_stiffness_n_per_m() - 1.6e6).abs() < 1.0);
        assert_eq!(p.couplings.len(), 2);
        let c1 = p.coupling_near(3500.0).unwrap();
        assert_eq!(c1.mu_range, [0.28, 0.38]);
        assert_eq!(p.meso_coupling_2.patch_sizes_m.len(), 7);
        assert!((p.meso_coupling_1.unstable_fraction - 0.651).abs() < 1e-12);
    }
}
