//! Model updating: fit scene parameters (any numeric field of the scene format, within
//! bounds) to measured or published targets of the rig: labelled normal-mode frequencies
//! of a body (the paper's Table 2), how many modes a body has below a frequency, the
//! static axial stiffness (the paper's 200 N at 125 um), and modes of the tied system on a
//! contact set picked by their make-up on the free-interface modes (the pin's pitch with
//! the face bonded to the disc, the partner of both of the paper's couplings).
//!
//! The spec format is in `docs/calibrate.md`; [`spec`] reads and checks it, [`evaluate`](mod@evaluate)
//! measures one scene, [`fit`] runs the search.

mod check;
pub mod evaluate;
pub mod fit;
mod search;
pub mod spec;
mod tied;

pub use evaluate::{evaluate, Evaluation, Measured};
pub use fit::{calibrate, scene_at, FitResult, Step};
pub use spec::{
    CalibrationSpec, Method, Parameter, Scale, Search, SpecError, SweepSearch, Target, TargetKind,
};
