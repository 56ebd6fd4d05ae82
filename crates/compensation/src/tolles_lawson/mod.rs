//! The Tolles-Lawson / Leliak interference model.

pub mod design;
pub mod eddy_lag;
pub mod extra_select;
pub mod fit_ls;
pub mod lag_select;
pub mod online;
pub mod segments;
pub mod terms;

pub use design::{Design, Magnitude};
pub use terms::{
    Convention, DEFAULT_BT_SCALE_NT, Differencing, ExtraRequest, ExtraSeries, ExtraTerm, TermGroup,
    TermSet,
};
