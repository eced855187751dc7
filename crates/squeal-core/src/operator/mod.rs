//! What every solver works on and returns: one quadratic eigenproblem ([`Qep`]), the
//! frictional operator of one contact set with its mu-independent and friction parts
//! apart ([`FrictionalOperator`]), and the modes of a band with the report of their solve
//! ([`ComplexModes`], [`RealModes`], [`SolveInfo`]).

mod frictional;
mod modes;
mod qep;

pub use frictional::{FrictionalOperator, LazyPair, ModalPair, RealModePair};
pub use modes::{
    classify, needs_condition, ComplexModes, RealModes, SolveInfo, Stability, StopReason, Verdict,
    BACKWARD_ERROR_FLOOR, MIN_COND, SQRT_RULE,
};
pub use qep::{check_qep, Qep};
