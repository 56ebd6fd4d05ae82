//! The Tolles-Lawson / Leliak interference model.
//!
//! | file | contents |
//! |---|---|
//! | [`terms`] | the terms and their columns, derivative conventions |
//! | [`design`] | the design matrix, interference of a model (first-order or exact magnitude) |
//! | [`fit_ls`] | band-pass least squares |
//! | [`eddy_lag`], [`lag_select`], [`extra_select`] | lagged eddy currents and extra channels, their tests |
//! | [`segments`] | splitting a flight into runs |
//! | [`online`] | a model applied sample by sample (latency 0) |
//! | [`adaptive`] | the same with coefficients updated as samples arrive |
//! | [`rls`] | recursive least squares with forgetting (the adaptive baseline) |

pub mod adaptive;
pub mod design;
pub mod eddy_lag;
pub mod extra_select;
pub mod fit_ls;
pub mod lag_select;
pub mod online;
pub mod rls;
pub mod segments;
pub mod terms;

pub use design::{Design, Magnitude};
pub use terms::{
    Convention, DEFAULT_BT_SCALE_NT, Differencing, ExtraRequest, ExtraSeries, ExtraTerm, TermGroup,
    TermSet,
};
