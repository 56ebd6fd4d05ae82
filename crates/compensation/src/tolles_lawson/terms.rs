//! Tolles-Lawson / Leliak design-matrix terms.
//!
//! Spec: `compensation.md`, "The interference model"; seed `000_…`, chapter 1.
//!
//! The aircraft field seen by the scalar sensor is, to first order,
//! `b = |B0| + eᵀ(K + L B0 + M dB0/dt)` with `e = B0/|B0|` measured by the
//! vector magnetometer as `e = B_F/|B_F|`. Expanding gives the design-matrix
//! columns (`Bt = |B_F|`, all products divided by `bt_scale`, default 50 000 nT):
//!
//! | group | columns | count |
//! |---|---|---|
//! | `p3` permanent | `e_x, e_y, e_z` | 3 |
//! | `i6` induced | `e_i B_j` for ij = xx, xy, xz, yy, yz, zz | 6 |
//! | `i5` | `i6` without zz | 5 |
//! | `e9` eddy | `e_i dB_j` for i, j in x, y, z, row-major | 9 |
//! | `e8` | `e9` without zz | 8 |
//! | `l9` lagged eddy | `e_i g_j` for each lag `τ`, row-major | 9 per `τ` |
//! | `bias` | 1 | 1 |
//!
//! (`e_i B_j = Bt e_i e_j`.) Because `eᵀe = 1` and `eᵀde = 0`, `p3+i6+e9` has two
//! near-exact collinearities; `p3+i5+e8` are the 16 observable parameters of
//! the thesis. Columns always come in the order of the table, whatever order
//! the user names the groups in.
//!
//! The lagged eddy groups are aeromag's extension of the Leliak model (not in
//! the seed): an eddy-current loop with inductance `L` and resistance `R`
//! obeys `L di/dt + R i = −A n·dB/dt`, so its current — and its field at the
//! sensor — follows `dB/dt` through a first-order lag of time constant
//! `τ = L/R`. The classical `e9` columns assume `τ → 0`; for aircraft skins
//! and frames `τ` is 0.1–1 s, which at the 0.1–0.9 Hz calibration band is a
//! phase lag of 4–80° that `e9` cannot represent. `g_j = L_τ[dB_j]` is that
//! lag applied to the derivative ([`super::eddy_lag::FirstOrderLag`]); the
//! projection on `e` stays instantaneous, as the field of the current is. The
//! lags `τ` (s) are part of the [`TermSet`] ([`TermSet::with_eddy_lags`]).
//! There is no lagged `zz`-less variant: `eᵀde = 0` holds at one instant,
//! but `e(t)ᵀ L_τ[dB](t)` mixes `e` at `t` with `dB` over the past `τ`, so
//! `e_z g_z` carries information the other eight columns do not (on a
//! simulated box, dropping it leaves 4× more of the eddy field unexplained).
//!
//! **Extra regressors** ([`ExtraTerm`], `--extra cur_strb,cur_flap:lag`):
//! any recorded channel `x` — typically the current of on-board equipment —
//! enters as the three columns `e_i x` (named `<channel>:e_x`, …), after
//! every group. A current loop fixed in the airframe makes a field `k I`
//! fixed in body axes, whose effect on the total field is `eᵀk I = Σ_i k_i
//! e_i I` (to first order): a plain column `I` would hold only one heading's
//! projection, and leaves tens of nT on a cabin sensor when the aircraft
//! turns. A loop whose field lags its current (eddy currents induced in
//! nearby structure by a switching load, time constant `τ`) adds the columns
//! `e_i L_τ[x]` (`<channel>:lag:e_x`, …) with the same first-order lag as
//! the eddy terms ([`super::eddy_lag::FirstOrderLag`]); `τ` is chosen on the
//! calibration flight by the likelihood-ratio test of the eddy lags
//! ([`super::lag_select`]). The coefficients are in nT per unit of the
//! channel (nT/A for a current).
//!
//! Derivative conventions ([`Convention`]):
//! * `Physical` (default): `dB_j` is the time derivative in nT/s, a central
//!   difference over the actual time stamps, first-order one-sided at the ends,
//!   so coefficients do not depend on the sampling rate.
//! * `MagNav`: MagNav.jl's `create_TL_A`, bit for bit: `dB_j` is the
//!   per-sample central difference `(x[i+1] − x[i−1])/2`, `x[1] − x[0]` and
//!   `x[n−1] − x[n−2]` at the ends, not divided by the sampling interval.

use crate::error::{CompError, Result};
use serde::{Deserialize, Serialize};

/// Default scale of the induced and eddy columns, nT.
pub const DEFAULT_BT_SCALE_NT: f64 = 50_000.0;

/// A group of Tolles-Lawson terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum TermGroup {
    /// Permanent: `e_x, e_y, e_z`.
    P3,
    /// Induced, all six products.
    I6,
    /// Induced without `zz`.
    I5,
    /// Eddy currents, all nine products.
    E9,
    /// Eddy currents without `zz`.
    E8,
    /// Lagged eddy currents, all nine products, one block per lag.
    L9,
    /// A constant column.
    Bias,
}

impl TermGroup {
    /// The group's name as written in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TermGroup::P3 => "p3",
            TermGroup::I6 => "i6",
            TermGroup::I5 => "i5",
            TermGroup::E9 => "e9",
            TermGroup::E8 => "e8",
            TermGroup::L9 => "l9",
            TermGroup::Bias => "bias",
        }
    }

    fn parse(s: &str) -> Result<Self> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "p3" | "p" | "permanent" => TermGroup::P3,
            "i6" | "i" | "induced" => TermGroup::I6,
            "i5" => TermGroup::I5,
            "e9" | "e" | "eddy" => TermGroup::E9,
            "e8" => TermGroup::E8,
            "l9" => TermGroup::L9,
            "bias" | "b" => TermGroup::Bias,
            other => {
                return Err(CompError::InvalidTerms {
                    reason: format!(
                        "unknown term group `{other}` (use p3, i6, i5, e9, e8, l9, bias)"
                    ),
                });
            }
        })
    }
}

/// How the field derivative `dB_j` of the eddy-current columns is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Convention {
    /// Time derivative in nT/s over the actual time stamps.
    #[default]
    Physical,
    /// MagNav.jl `create_TL_A`: per-sample central difference, not divided by dt.
    #[cfg_attr(feature = "clap", value(name = "magnav"))]
    MagNav,
}

impl std::fmt::Display for Convention {
    /// `physical` or `magnav`, as in files and on the command line.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Convention::Physical => "physical",
            Convention::MagNav => "magnav",
        })
    }
}

impl std::str::FromStr for Convention {
    type Err = CompError;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "physical" => Ok(Convention::Physical),
            "magnav" => Ok(Convention::MagNav),
            o => Err(CompError::InvalidTerms {
                reason: format!("unknown derivative convention `{o}` (physical or magnav)"),
            }),
        }
    }
}

/// A validated, ordered set of term groups, with the eddy-current lags of
/// the `l9`/`l8` groups and the extra regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TermSet {
    groups: Vec<TermGroup>,
    /// Time constants `τ` (s, ascending) of the lagged eddy groups; empty
    /// without them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    eddy_lags_s: Vec<f64>,
    /// Extra regressors, in column order (module docs); empty without them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    extras: Vec<ExtraTerm>,
}

/// An extra regressor of a fitted model: the recorded channel `channel`
/// times the direction cosines, and with `lag_s = Some(τ)` also the channel
/// through the first-order lag `τ` times the direction cosines (module
/// docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtraTerm {
    /// Column name in the flight (e.g. `cur_strb`).
    pub channel: String,
    /// Time constant of the lagged columns, s (`None`: no lagged columns).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lag_s: Option<f64>,
}

impl ExtraTerm {
    /// The channel's instantaneous columns only.
    pub fn new(channel: impl Into<String>) -> Self {
        Self {
            channel: channel.into(),
            lag_s: None,
        }
    }

    /// The channel's columns and its lagged columns of time constant
    /// `lag_s` (s).
    pub fn lagged(channel: impl Into<String>, lag_s: f64) -> Self {
        Self {
            channel: channel.into(),
            lag_s: Some(lag_s),
        }
    }
}

/// An extra regressor as the user asks for it: `cur_strb` (the channel's
/// columns) or `cur_flap:lag` (also its lagged columns, the lag to be
/// chosen on the calibration flight).
///
/// ```
/// use aeromag_compensation::tolles_lawson::ExtraRequest;
/// let r = ExtraRequest::parse_list("cur_strb, cur_flap:lag")?;
/// assert_eq!(r[1], ExtraRequest { channel: "cur_flap".into(), lag: true });
/// assert!(ExtraRequest::parse_list("cur_strb:lagg").is_err());
/// # Ok::<(), aeromag_compensation::CompError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExtraRequest {
    /// Column name in the flight.
    pub channel: String,
    /// Also through a first-order lag fitted on the calibration flight.
    pub lag: bool,
}

impl ExtraRequest {
    /// Parse `name[:lag],name[:lag],…` (spaces ignored; an empty text is no
    /// request). A name may appear once.
    pub fn parse_list(s: &str) -> Result<Vec<Self>> {
        let mut out: Vec<Self> = Vec::new();
        for item in s.split(',').map(str::trim).filter(|t| !t.is_empty()) {
            let (name, lag) = match item.split_once(':') {
                None => (item, false),
                Some((name, "lag")) => (name.trim(), true),
                Some((_, other)) => {
                    return Err(CompError::InvalidTerms {
                        reason: format!(
                            "extra regressor `{item}`: unknown suffix `:{other}` (only `:lag`)"
                        ),
                    });
                }
            };
            check_channel_name(name)?;
            if out.iter().any(|r| r.channel == name) {
                return Err(CompError::InvalidTerms {
                    reason: format!("extra regressor `{name}` is given twice"),
                });
            }
            out.push(Self {
                channel: name.to_string(),
                lag,
            });
        }
        Ok(out)
    }
}

impl std::fmt::Display for ExtraRequest {
    /// `name` or `name:lag`, as on the command line.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.channel)?;
        if self.lag {
            f.write_str(":lag")?;
        }
        Ok(())
    }
}

fn check_channel_name(name: &str) -> Result<()> {
    if name.is_empty() || name.contains([',', ':']) || name.chars().any(char::is_whitespace) {
        return Err(CompError::InvalidTerms {
            reason: format!("extra regressor `{name}`: not a column name"),
        });
    }
    Ok(())
}

/// The inputs of one extra regressor's columns over a run of samples: the
/// channel and, when the term has a lag, the lagged channel (empty slice
/// otherwise).
#[derive(Debug, Clone, Copy)]
pub struct ExtraSeries<'a> {
    /// The channel.
    pub values: &'a [f64],
    /// The channel through the term's lag (empty without a lag).
    pub lagged: &'a [f64],
}

/// The eddy-current lags a model may have (s): the decay times of an
/// airframe's eddy currents are some tens of milliseconds to about a second
/// (the lag search tries 0.1–1 s); outside this range a lag is a typing
/// error, and a lag far below the sample interval makes the lagged column
/// the plain eddy column.
pub const EDDY_LAG_RANGE_S: (f64, f64) = (0.01, 10.0);

/// Each of `taus_s` within [`EDDY_LAG_RANGE_S`].
fn check_eddy_lags(taus_s: &[f64]) -> Result<()> {
    let (lo, hi) = EDDY_LAG_RANGE_S;
    match taus_s.iter().find(|t| !(lo..=hi).contains(*t)) {
        Some(t) => Err(CompError::InvalidTerms {
            reason: format!(
                "eddy-current lag {} s: must be from {lo} to {hi} s",
                aeromag_core::error::shown(*t)
            ),
        }),
        None => Ok(()),
    }
}

const XYZ: [&str; 3] = ["x", "y", "z"];
const PAIRS6: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// One design-matrix column: what it multiplies (the module's table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Column {
    /// `e_i`.
    Direction(usize),
    /// `e_i s_j / bt_scale`, `s` the field, its derivative or a lagged
    /// derivative.
    Product {
        /// Axis of the direction cosine.
        i: usize,
        /// What `s` is.
        source: Source,
        /// Axis of `s`.
        j: usize,
    },
    /// `1`.
    Bias,
    /// `e_i x`, `x` the extra regressor `k` ([`TermSet::extras`]) or, with
    /// `lagged`, its lagged series.
    Extra {
        /// Axis of the direction cosine.
        i: usize,
        /// Index of the extra regressor.
        k: usize,
        /// The lagged series rather than the channel itself.
        lagged: bool,
    },
}

/// The second factor of a [`Column::Product`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The vector field `B_j`, nT.
    Field,
    /// Its derivative `dB_j`.
    Derivative,
    /// The derivative through the lag of index `k` of
    /// [`TermSet::eddy_lags_s`].
    Lagged(usize),
}

/// `e s / bt_scale`: the one formula of every product column, shared by
/// the row-wise ([`TermSet::row`]) and column-wise ([`TermSet::columns`])
/// builders so that they give the same bits.
#[inline(always)]
fn product(e: f64, s: f64, bt_scale: f64) -> f64 {
    e * s / bt_scale
}

/// `|B|`, as both builders compute it.
#[inline(always)]
fn magnitude(b: [f64; 3]) -> f64 {
    (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt()
}

impl TermSet {
    /// The thesis' 16 observable parameters: `p3, i5, e8`.
    pub fn observable16() -> Self {
        Self {
            groups: vec![TermGroup::P3, TermGroup::I5, TermGroup::E8],
            eddy_lags_s: Vec::new(),
            extras: Vec::new(),
        }
    }

    /// All 18 classical terms `p3, i6, e9` (two near-collinearities).
    pub fn full18() -> Self {
        Self {
            groups: vec![TermGroup::P3, TermGroup::I6, TermGroup::E9],
            eddy_lags_s: Vec::new(),
            extras: Vec::new(),
        }
    }

    /// A set from groups; sorted into the canonical order. Rejects an empty
    /// set, duplicates, and both variants of one family (`i6`+`i5`, `e9`+`e8`).
    /// The lagged group needs its lags: [`TermSet::with_eddy_lags`].
    pub fn new(groups: &[TermGroup]) -> Result<Self> {
        let mut g = groups.to_vec();
        g.sort();
        g.dedup();
        if g.is_empty() {
            return Err(CompError::InvalidTerms {
                reason: "no term groups given".into(),
            });
        }
        if g.contains(&TermGroup::I6) && g.contains(&TermGroup::I5) {
            return Err(CompError::InvalidTerms {
                reason: "choose one of i6 and i5".into(),
            });
        }
        if g.contains(&TermGroup::E9) && g.contains(&TermGroup::E8) {
            return Err(CompError::InvalidTerms {
                reason: "choose one of e9 and e8".into(),
            });
        }
        Ok(Self {
            groups: g,
            eddy_lags_s: Vec::new(),
            extras: Vec::new(),
        })
    }

    /// This set with the lagged eddy group `l9` for the lags `taus_s` (s,
    /// each finite and > 0; sorted, duplicates removed). An empty `taus_s`
    /// removes the lagged group. Errors without an eddy group (`e8`/`e9`).
    pub fn with_eddy_lags(&self, taus_s: &[f64]) -> Result<Self> {
        let mut groups: Vec<TermGroup> = self
            .groups
            .iter()
            .copied()
            .filter(|g| *g != TermGroup::L9)
            .collect();
        if taus_s.is_empty() {
            return Ok(Self {
                groups,
                eddy_lags_s: Vec::new(),
                extras: self.extras.clone(),
            });
        }
        check_eddy_lags(taus_s)?;
        if !groups
            .iter()
            .any(|g| matches!(g, TermGroup::E9 | TermGroup::E8))
        {
            return Err(CompError::InvalidTerms {
                reason: "eddy-current lags need an eddy group (e8 or e9)".into(),
            });
        }
        groups.push(TermGroup::L9);
        groups.sort();
        let mut taus = taus_s.to_vec();
        taus.sort_by(f64::total_cmp);
        taus.dedup();
        Ok(Self {
            groups,
            eddy_lags_s: taus,
            extras: self.extras.clone(),
        })
    }

    /// This set with the extra regressors `extras` (replacing any it has),
    /// in that column order. Rejects a channel named twice, an empty name
    /// and a lag that is not finite and > 0.
    pub fn with_extras(&self, extras: &[ExtraTerm]) -> Result<Self> {
        let set = Self {
            extras: extras.to_vec(),
            ..self.clone()
        };
        set.validate_extras()?;
        Ok(set)
    }

    /// The extra regressors, in column order.
    pub fn extras(&self) -> &[ExtraTerm] {
        &self.extras
    }

    fn validate_extras(&self) -> Result<()> {
        for (k, x) in self.extras.iter().enumerate() {
            check_channel_name(&x.channel)?;
            if self.extras[..k].iter().any(|o| o.channel == x.channel) {
                return Err(CompError::InvalidTerms {
                    reason: format!("extra regressor `{}` is given twice", x.channel),
                });
            }
            if let Some(t) = x.lag_s
                && !(t.is_finite() && t > 0.0)
            {
                return Err(CompError::InvalidTerms {
                    reason: format!("lag {t} s of `{}`: must be finite and > 0", x.channel),
                });
            }
        }
        Ok(())
    }

    /// The lags `τ` (s) of the lagged eddy groups (empty without them).
    pub fn eddy_lags_s(&self) -> &[f64] {
        &self.eddy_lags_s
    }

    /// Check the lags against the groups (a set read from a file).
    pub fn validate(&self) -> Result<()> {
        if self.groups.contains(&TermGroup::L9) == self.eddy_lags_s.is_empty() {
            return Err(CompError::InvalidTerms {
                reason: "the lagged eddy group l9 and the eddy lags must be given together".into(),
            });
        }
        check_eddy_lags(&self.eddy_lags_s)?;
        self.validate_extras()
    }

    /// Parse a comma-separated list such as `p3,i5,e8,bias`.
    pub fn parse(s: &str) -> Result<Self> {
        let groups = s
            .split(',')
            .filter(|t| !t.trim().is_empty())
            .map(TermGroup::parse)
            .collect::<Result<Vec<_>>>()?;
        Self::new(&groups)
    }

    /// The groups, in canonical order.
    pub fn groups(&self) -> &[TermGroup] {
        &self.groups
    }

    /// Whether any eddy-current group is present (needs derivatives).
    pub fn has_eddy(&self) -> bool {
        self.groups
            .iter()
            .any(|g| matches!(g, TermGroup::E9 | TermGroup::E8 | TermGroup::L9))
    }

    /// The index of the `bias` column, if the terms have one.
    pub fn bias_column(&self) -> Option<usize> {
        self.column_indices(|c| c == Column::Bias).first().copied()
    }

    /// The indices of the columns for which `pick` holds, in column order.
    pub fn column_indices(&self, mut pick: impl FnMut(Column) -> bool) -> Vec<usize> {
        let (mut k, mut out) = (0, Vec::new());
        self.for_each_column(|c| {
            if pick(c) {
                out.push(k);
            }
            k += 1;
        });
        out
    }

    /// Column names, e.g. `p_x`, `i_xy`, `e_zy`, `bias`, in column order.
    pub fn column_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for g in &self.groups {
            match g {
                TermGroup::P3 => names.extend(XYZ.iter().map(|a| format!("p_{a}"))),
                TermGroup::I6 | TermGroup::I5 => {
                    let n = if *g == TermGroup::I6 { 6 } else { 5 };
                    names.extend(
                        PAIRS6[..n]
                            .iter()
                            .map(|&(i, j)| format!("i_{}{}", XYZ[i], XYZ[j])),
                    );
                }
                TermGroup::E9 | TermGroup::E8 => {
                    let n = if *g == TermGroup::E9 { 9 } else { 8 };
                    names.extend((0..n).map(|k| format!("e_{}{}", XYZ[k / 3], XYZ[k % 3])));
                }
                TermGroup::L9 => {
                    let many = self.eddy_lags_s.len() > 1;
                    for lag in 1..=self.eddy_lags_s.len() {
                        let prefix = if many { format!("l{lag}") } else { "l".into() };
                        names.extend(
                            (0..9).map(|k| format!("{prefix}_{}{}", XYZ[k / 3], XYZ[k % 3])),
                        );
                    }
                }
                TermGroup::Bias => names.push("bias".into()),
            }
        }
        for x in &self.extras {
            names.extend(XYZ.iter().map(|a| format!("{}:e_{a}", x.channel)));
            if x.lag_s.is_some() {
                names.extend(XYZ.iter().map(|a| format!("{}:lag:e_{a}", x.channel)));
            }
        }
        names
    }

    /// Number of columns.
    pub fn n_columns(&self) -> usize {
        self.groups
            .iter()
            .map(|g| match g {
                TermGroup::P3 => 3,
                TermGroup::I6 => 6,
                TermGroup::I5 => 5,
                TermGroup::E9 => 9,
                TermGroup::E8 => 8,
                TermGroup::L9 => 9 * self.eddy_lags_s.len(),
                TermGroup::Bias => 1,
            })
            .sum::<usize>()
            + self
                .extras
                .iter()
                .map(|x| if x.lag_s.is_some() { 6 } else { 3 })
                .sum::<usize>()
    }

    /// The lags of the extra regressors that have one, s.
    pub fn extra_lags_s(&self) -> impl Iterator<Item = f64> + '_ {
        self.extras.iter().filter_map(|x| x.lag_s)
    }

    /// Comma-separated group names, e.g. `p3,i5,e8` (the extra regressors
    /// are not groups: [`TermSet::extras`]).
    pub fn to_spec_string(&self) -> String {
        self.groups
            .iter()
            .map(|g| g.name())
            .collect::<Vec<_>>()
            .join(",")
    }

    /// One design-matrix row into `out` (length [`TermSet::n_columns`]) from
    /// the vector field `b` (nT, body frame), its derivative `db` (units of
    /// the convention) and the lagged derivatives `lagged[k] = L_τk[db]`, one
    /// per [`TermSet::eddy_lags_s`], and the extra regressors `extra[k] =
    /// [x_k, L_τ[x_k]]` (the lagged value is unused without a lag; missing
    /// inputs give NaN columns). Non-finite inputs give non-finite rows,
    /// never a panic.
    pub fn row(
        &self,
        b: [f64; 3],
        db: [f64; 3],
        lagged: &[[f64; 3]],
        extra: &[[f64; 2]],
        bt_scale: f64,
        out: &mut [f64],
    ) {
        self.row_along(b, b, db, lagged, extra, bt_scale, out)
    }

    /// [`TermSet::row`] with the direction cosines `e = d/|d|` of the
    /// vector `dir` (the total field `b + ΔB` in the Gauss–Newton steps of
    /// the exact-magnitude model; [`TermSet::columns_into`] does the same
    /// column by column).
    #[allow(clippy::too_many_arguments)]
    pub fn row_along(
        &self,
        dir: [f64; 3],
        b: [f64; 3],
        db: [f64; 3],
        lagged: &[[f64; 3]],
        extra: &[[f64; 2]],
        bt_scale: f64,
        out: &mut [f64],
    ) {
        let bt = magnitude(dir);
        let e = [dir[0] / bt, dir[1] / bt, dir[2] / bt];
        // Block by block ([`Self::for_each_block`]; a test compares the
        // row with [`Self::for_each_column`]): fixed-length loops, which the
        // compiler unrolls and vectorises, instead of one call per column.
        let nine = |s: [f64; 3], out: &mut [f64]| {
            for (m, o) in out.iter_mut().enumerate() {
                *o = product(e[m / 3], s[m % 3], bt_scale);
            }
        };
        let mut k = 0;
        self.for_each_block(|block| match block {
            Block::Directions => {
                out[k..k + 3].copy_from_slice(&e);
                k += 3;
            }
            Block::Field(n) => {
                for (o, &(i, j)) in out[k..k + n].iter_mut().zip(&PAIRS6) {
                    *o = product(e[i], b[j], bt_scale);
                }
                k += n;
            }
            Block::Derivative(9) => {
                nine(db, &mut out[k..k + 9]);
                k += 9;
            }
            Block::Derivative(n) => {
                let mut all = [0.0; 9];
                nine(db, &mut all);
                out[k..k + n].copy_from_slice(&all[..n]);
                k += n;
            }
            Block::Lagged(lag) => {
                nine(
                    lagged.get(lag).copied().unwrap_or([f64::NAN; 3]),
                    &mut out[k..k + 9],
                );
                k += 9;
            }
            Block::Bias => {
                out[k] = 1.0;
                k += 1;
            }
            Block::Extra { k: x, lagged } => {
                let v = extra.get(x).map_or(f64::NAN, |v| v[usize::from(lagged)]);
                for ei in e {
                    out[k] = ei * v;
                    k += 1;
                }
            }
        });
    }

    /// The design matrix column by column (`out[k][n]`, the same values as
    /// [`TermSet::row`] for every sample `n`, bit for bit), from the vector
    /// field `b[axis][n]`, its derivative `db` and the lagged derivatives
    /// `lagged[lag][axis][n]` and the extra regressors `extra[k]`; all
    /// slices of equal length (missing inputs give NaN columns). Each column
    /// is one loop over the samples, which the compiler vectorises.
    pub fn columns(
        &self,
        b: [&[f64]; 3],
        db: [&[f64]; 3],
        lagged: &[[&[f64]; 3]],
        extra: &[ExtraSeries],
        bt_scale: f64,
    ) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        self.columns_into(
            b,
            b,
            db,
            lagged,
            extra,
            bt_scale,
            &mut Default::default(),
            &mut out,
        );
        out
    }

    /// [`TermSet::columns`] into `out`, reusing its allocations and those of
    /// the direction-cosine scratch `e` (one allocation per column for the
    /// first block, none for the next blocks of the same length), with the
    /// direction cosines `e = d/|d|` of the vector `dir` (the field `b`
    /// itself in the Tolles-Lawson model; the total field `b + ΔB` in the
    /// Gauss–Newton steps of the exact-magnitude model,
    /// [`super::design::Magnitude::Exact`]).
    #[allow(clippy::too_many_arguments)]
    pub fn columns_into(
        &self,
        dir: [&[f64]; 3],
        b: [&[f64]; 3],
        db: [&[f64]; 3],
        lagged: &[[&[f64]; 3]],
        extra: &[ExtraSeries],
        bt_scale: f64,
        e: &mut [Vec<f64>; 3],
        out: &mut Vec<Vec<f64>>,
    ) {
        let mut kinds = Vec::with_capacity(self.n_columns());
        self.for_each_column(|c| kinds.push(c));
        out.resize_with(kinds.len(), Vec::new);
        aeromag_core::simd::run(DesignColumns {
            kinds: &kinds,
            dir,
            b,
            db,
            lagged,
            extra,
            bt_scale,
            e,
            out,
        });
    }

    /// Every column in order, as a [`Column`] (the module's table).
    pub fn for_each_column(&self, mut f: impl FnMut(Column)) {
        let products = |i: usize, source: Source, j: usize| Column::Product { i, source, j };
        self.for_each_block(|b| match b {
            Block::Directions => (0..3).for_each(|i| f(Column::Direction(i))),
            Block::Field(n) => {
                for &(i, j) in &PAIRS6[..n] {
                    f(products(i, Source::Field, j));
                }
            }
            Block::Derivative(n) => {
                for m in 0..n {
                    f(products(m / 3, Source::Derivative, m % 3));
                }
            }
            Block::Lagged(lag) => {
                for m in 0..9 {
                    f(products(m / 3, Source::Lagged(lag), m % 3));
                }
            }
            Block::Bias => f(Column::Bias),
            Block::Extra { k, lagged } => (0..3).for_each(|i| f(Column::Extra { i, k, lagged })),
        });
    }

    /// The blocks of columns in order: the one place that orders the
    /// columns ([`Self::for_each_column`] and [`Self::row_along`] follow it).
    #[inline(always)]
    fn for_each_block(&self, mut f: impl FnMut(Block)) {
        for g in &self.groups {
            match g {
                TermGroup::P3 => f(Block::Directions),
                TermGroup::I6 => f(Block::Field(6)),
                TermGroup::I5 => f(Block::Field(5)),
                TermGroup::E9 => f(Block::Derivative(9)),
                TermGroup::E8 => f(Block::Derivative(8)),
                TermGroup::L9 => (0..self.eddy_lags_s.len()).for_each(|lag| f(Block::Lagged(lag))),
                TermGroup::Bias => f(Block::Bias),
            }
        }
        for (k, x) in self.extras.iter().enumerate() {
            f(Block::Extra { k, lagged: false });
            if x.lag_s.is_some() {
                f(Block::Extra { k, lagged: true });
            }
        }
    }
}

/// A block of consecutive columns ([`TermSet::for_each_block`]).
#[derive(Debug, Clone, Copy)]
enum Block {
    /// `e_x, e_y, e_z`.
    Directions,
    /// The first `n` products `e_i B_j` of [`PAIRS6`].
    Field(usize),
    /// The first `n` products `e_i dB_j` (`i` major).
    Derivative(usize),
    /// The nine products `e_i L_τ[dB_j]` of lag `τ` number `lag`.
    Lagged(usize),
    /// The constant.
    Bias,
    /// `e_i x_k` (or `e_i L[x_k]`) of extra regressor `k`.
    Extra { k: usize, lagged: bool },
}

/// The arguments of [`TermSet::columns_into`] as a kernel compiled with
/// AVX where the processor has it ([`aeromag_core::simd`]): the same
/// arithmetic in the same order (same bits), four lanes per instruction,
/// which matters most for the divisions of the product columns.
struct DesignColumns<'a, 'x> {
    kinds: &'a [Column],
    dir: [&'a [f64]; 3],
    b: [&'a [f64]; 3],
    db: [&'a [f64]; 3],
    lagged: &'a [[&'a [f64]; 3]],
    extra: &'a [ExtraSeries<'x>],
    bt_scale: f64,
    e: &'a mut [Vec<f64>; 3],
    out: &'a mut [Vec<f64>],
}

impl aeromag_core::simd::Kernel for DesignColumns<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        let (b, bt_scale) = (self.b, self.bt_scale);
        let n = b[0].len();
        // e[0] holds |B| until e[1] and e[2] are divided by it, then
        // becomes B_x/|B| in place (no fourth buffer).
        let [e0, e1, e2] = self.e;
        let (dx, dy, dz) = (&self.dir[0][..n], &self.dir[1][..n], &self.dir[2][..n]);
        e0.resize(n, 0.0);
        for (k, t) in e0.iter_mut().enumerate() {
            *t = magnitude([dx[k], dy[k], dz[k]]);
        }
        for (ei, d) in [(&mut *e1, dy), (&mut *e2, dz)] {
            ei.resize(n, 0.0);
            for ((v, x), t) in ei.iter_mut().zip(d).zip(e0.iter()) {
                *v = x / t;
            }
        }
        for (v, x) in e0.iter_mut().zip(dx) {
            *v = x / *v;
        }
        let e = [&e0[..n], &e1[..n], &e2[..n]];
        for (col, &c) in self.out.iter_mut().zip(self.kinds) {
            col.resize(n, 0.0);
            match c {
                Column::Direction(i) => col.copy_from_slice(e[i]),
                Column::Product { i, source, j } => {
                    let s = match source {
                        Source::Field => b[j],
                        Source::Derivative => self.db[j],
                        Source::Lagged(l) => match self.lagged.get(l) {
                            Some(g) => g[j],
                            None => {
                                col.fill(f64::NAN);
                                continue;
                            }
                        },
                    };
                    for ((o, &ei), &sj) in col.iter_mut().zip(e[i]).zip(&s[..n]) {
                        *o = product(ei, sj, bt_scale);
                    }
                }
                Column::Bias => col.fill(1.0),
                Column::Extra { i, k, lagged } => {
                    let x = self
                        .extra
                        .get(k)
                        .map(|x| if lagged { x.lagged } else { x.values });
                    match x {
                        Some(x) if x.len() >= n => {
                            for ((o, &ei), &xk) in col.iter_mut().zip(e[i]).zip(&x[..n]) {
                                *o = ei * xk;
                            }
                        }
                        _ => col.fill(f64::NAN),
                    }
                }
            }
        }
    }
}

impl std::fmt::Display for TermSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.to_spec_string())
    }
}

/// Which samples a derivative is differenced over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Differencing {
    /// Central differences, one-sided at a segment's ends: the batch path
    /// (every sample's neighbours are known).
    #[default]
    Centred,
    /// Backward differences `x[i] − x[i−1]` (divided by `t[i] − t[i−1]`
    /// under [`Convention::Physical`]), 0 at a segment's first sample: the
    /// causal convention, which needs no later sample (latency 0; the
    /// online compensator, `compensate --causal`).
    Backward,
}

impl Differencing {
    pub(crate) fn is_centred(&self) -> bool {
        *self == Differencing::Centred
    }
}

/// Derivative of a series under a convention.
///
/// `Physical`: `(x[i+1] − x[i−1]) / (t[i+1] − t[i−1])`, one-sided at the
/// ends, nT/s. `MagNav`: `(x[i+1] − x[i−1]) / 2`, one-sided at the ends,
/// per sample (MagNav.jl `fdm(x; scheme=:central)`). Series of fewer than
/// 3 samples give zeros (MagNav's behaviour for the central scheme).
pub fn derivative(x: &[f64], t: &[f64], convention: Convention) -> Vec<f64> {
    let mut d = Vec::new();
    derivative_into(x, t, convention, Differencing::Centred, &mut d);
    d
}

/// The derivative of `x` under `convention` and `differencing` into `d`
/// (resized to `x.len()`, its allocation reused): [`derivative`] when
/// centred; backward differences otherwise ([`Differencing::Backward`]).
pub fn derivative_into(
    x: &[f64],
    t: &[f64],
    convention: Convention,
    differencing: Differencing,
    d: &mut Vec<f64>,
) {
    derivative_rows_into(x, t, convention, differencing, 0..x.len(), d);
}

/// Rows `rows` of [`derivative_into`] of the whole series `x` into `d`
/// (resized to `rows.len()`): the same values, computed from the
/// neighbours of those rows only, so that a long series can be
/// differentiated block by block without a full-length buffer.
pub fn derivative_rows_into(
    x: &[f64],
    t: &[f64],
    convention: Convention,
    differencing: Differencing,
    rows: std::ops::Range<usize>,
    d: &mut Vec<f64>,
) {
    let n = x.len();
    d.clear();
    d.resize(rows.len(), 0.0);
    let first = rows.start;
    if differencing == Differencing::Backward {
        for i in rows.start.max(1)..rows.end {
            d[i - first] = backward_difference(convention, x[i - 1], x[i], t[i - 1], t[i]);
        }
        return;
    }
    if n < 3 {
        return;
    }
    let interior = rows.start.max(1)..rows.end.min(n - 1);
    match convention {
        Convention::MagNav => {
            for i in interior {
                d[i - first] = (x[i + 1] - x[i - 1]) / 2.0;
            }
            if rows.contains(&0) {
                d[0] = x[1] - x[0];
            }
            if rows.contains(&(n - 1)) {
                d[n - 1 - first] = x[n - 1] - x[n - 2];
            }
        }
        Convention::Physical => {
            for i in interior {
                d[i - first] = (x[i + 1] - x[i - 1]) / (t[i + 1] - t[i - 1]);
            }
            if rows.contains(&0) {
                d[0] = (x[1] - x[0]) / (t[1] - t[0]);
            }
            if rows.contains(&(n - 1)) {
                d[n - 1 - first] = (x[n - 1] - x[n - 2]) / (t[n - 1] - t[n - 2]);
            }
        }
    }
}

/// The backward difference of `x` from `(t0, x0)` to `(t1, x1)` under
/// `convention`: per second ([`Convention::Physical`]) or per sample.
pub fn backward_difference(convention: Convention, x0: f64, x1: f64, t0: f64, t1: f64) -> f64 {
    match convention {
        Convention::Physical => (x1 - x0) / (t1 - t0),
        Convention::MagNav => x1 - x0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_names() {
        assert_eq!(TermSet::observable16().n_columns(), 16);
        assert_eq!(TermSet::full18().n_columns(), 18);
        let t = TermSet::parse("bias,e8,p3,i5").unwrap();
        assert_eq!(t.to_spec_string(), "p3,i5,e8,bias");
        let names = t.column_names();
        assert_eq!(names.len(), 17);
        assert_eq!(names[0], "p_x");
        assert_eq!(names[7], "i_yz");
        assert_eq!(names[8], "e_xx");
        assert_eq!(names[15], "e_zy");
        assert_eq!(names[16], "bias");
        assert!(TermSet::parse("i5,i6").is_err());
        assert!(TermSet::parse("").is_err());
        assert!(TermSet::parse("p3,x7").is_err());
    }

    #[test]
    fn identities_of_the_full_set() {
        // eᵀe = 1: the induced xx+yy+zz columns sum to Bt/bt_scale;
        // eᵀdB = d|B|: the eddy diagonal sums to dBt/bt_scale.
        let t = TermSet::full18();
        let b = [20_000.0, -3_000.0, 45_000.0];
        let db = [1.5, -0.7, 0.2];
        let mut row = vec![0.0; 18];
        t.row(b, db, &[], &[], DEFAULT_BT_SCALE_NT, &mut row);
        let bt = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        let ind = row[3] + row[6] + row[8];
        assert!((ind - bt / DEFAULT_BT_SCALE_NT).abs() < 1e-15);
        let e = [b[0] / bt, b[1] / bt, b[2] / bt];
        let dbt = e[0] * db[0] + e[1] * db[1] + e[2] * db[2];
        assert!((row[9] + row[13] + row[17] - dbt / DEFAULT_BT_SCALE_NT).abs() < 1e-18);
    }

    #[test]
    fn lagged_groups() {
        let t = TermSet::observable16()
            .with_eddy_lags(&[0.8, 0.2, 0.8])
            .unwrap();
        assert_eq!(t.eddy_lags_s(), &[0.2, 0.8]);
        assert_eq!(t.to_spec_string(), "p3,i5,e8,l9");
        assert_eq!(t.n_columns(), 16 + 18);
        let names = t.column_names();
        assert_eq!(
            (
                names[16].as_str(),
                names[24].as_str(),
                names[25].as_str(),
                names[33].as_str()
            ),
            ("l1_xx", "l1_zz", "l2_xx", "l2_zz")
        );
        let one = TermSet::full18().with_eddy_lags(&[0.3]).unwrap();
        assert_eq!(one.column_names()[18], "l_xx");
        assert_eq!(one.with_eddy_lags(&[]).unwrap(), TermSet::full18());
        // Row: e_i g_j / bt_scale; a missing lagged input gives NaN, not a panic.
        let b: [f64; 3] = [20_000.0, -3_000.0, 45_000.0];
        let bt = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        let mut row = vec![0.0; one.n_columns()];
        one.row(
            b,
            [1.0, 2.0, 3.0],
            &[[0.5, -0.25, 2.0]],
            &[],
            DEFAULT_BT_SCALE_NT,
            &mut row,
        );
        assert!((row[18 + 5] - b[1] / bt * 2.0 / DEFAULT_BT_SCALE_NT).abs() < 1e-18);
        one.row(b, [1.0, 2.0, 3.0], &[], &[], DEFAULT_BT_SCALE_NT, &mut row);
        assert!(row[18..].iter().all(|v| v.is_nan()) && row[..18].iter().all(|v| v.is_finite()));
        // Bad lags and sets.
        assert!(
            TermSet::parse("p3,i5")
                .unwrap()
                .with_eddy_lags(&[0.3])
                .is_err()
        );
        assert!(TermSet::observable16().with_eddy_lags(&[0.0]).is_err());
        assert!(TermSet::observable16().with_eddy_lags(&[f64::NAN]).is_err());
        // Lags outside the physical range, in a setting and in a file.
        for tau in [1e-9, 0.009, 10.5, 1e6, 1e308] {
            let e = TermSet::observable16().with_eddy_lags(&[tau]).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("from 0.01 to 10 s"),
                "{e}"
            );
            let mut read = t.clone();
            read.eddy_lags_s = vec![tau];
            assert!(read.validate().is_err(), "{tau}");
        }
        for tau in [0.01, 10.0] {
            assert!(TermSet::observable16().with_eddy_lags(&[tau]).is_ok());
        }
        assert!(TermSet::parse("p3,e8,l9").unwrap().validate().is_err());
        assert!(t.validate().is_ok());
        // Serialised with its lags; a set without lags stays as before.
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(
            json,
            r#"{"groups":["p3","i5","e8","l9"],"eddy_lags_s":[0.2,0.8]}"#
        );
        assert_eq!(serde_json::from_str::<TermSet>(&json).unwrap(), t);
        assert_eq!(
            serde_json::to_string(&TermSet::observable16()).unwrap(),
            r#"{"groups":["p3","i5","e8"]}"#
        );
    }

    #[test]
    fn extra_regressors() {
        let t = TermSet::observable16()
            .with_extras(&[
                ExtraTerm::new("cur_strb"),
                ExtraTerm::lagged("cur_flap", 0.3),
            ])
            .unwrap();
        assert_eq!(t.n_columns(), 16 + 3 + 6);
        let names = t.column_names();
        assert_eq!(names.len(), t.n_columns());
        assert_eq!(
            (names[16].as_str(), names[18].as_str(), names[22].as_str()),
            ("cur_strb:e_x", "cur_strb:e_z", "cur_flap:lag:e_x")
        );
        // The lags survive a change of eddy lags, and the file form.
        let l = t.with_eddy_lags(&[0.2]).unwrap();
        assert_eq!(l.extras(), t.extras());
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(
            json,
            r#"{"groups":["p3","i5","e8"],"extras":[{"channel":"cur_strb"},{"channel":"cur_flap","lag_s":0.3}]}"#
        );
        assert_eq!(serde_json::from_str::<TermSet>(&json).unwrap(), t);
        // Row: e_i x and e_i L[x]; a missing input gives NaN, never a panic.
        let b: [f64; 3] = [20_000.0, -3_000.0, 45_000.0];
        let bt = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        let mut row = vec![0.0; t.n_columns()];
        t.row(b, [0.0; 3], &[], &[[2.0, 9.0], [4.0, 3.0]], 5e4, &mut row);
        assert_eq!(row[16], b[0] / bt * 2.0);
        assert_eq!(row[22 + 2], b[2] / bt * 3.0);
        assert_eq!(row[19 + 1], b[1] / bt * 4.0);
        t.row(b, [0.0; 3], &[], &[[2.0, 9.0]], 5e4, &mut row);
        assert!(row[19..].iter().all(|v| v.is_nan()) && row[..19].iter().all(|v| v.is_finite()));
        // Bad sets.
        for bad in [
            vec![ExtraTerm::new("a"), ExtraTerm::new("a")],
            vec![ExtraTerm::new("")],
            vec![ExtraTerm::new("a:b")],
            vec![ExtraTerm::lagged("a", 0.0)],
            vec![ExtraTerm::lagged("a", f64::INFINITY)],
        ] {
            assert!(
                TermSet::observable16().with_extras(&bad).is_err(),
                "{bad:?}"
            );
        }
        let r = ExtraRequest::parse_list(" cur_strb ,cur_flap:lag,").unwrap();
        assert_eq!(
            r.iter().map(ToString::to_string).collect::<Vec<_>>(),
            ["cur_strb", "cur_flap:lag"]
        );
        assert!(ExtraRequest::parse_list("").unwrap().is_empty());
        for bad in ["a,a:lag", "a:", "a b", ":lag"] {
            assert!(ExtraRequest::parse_list(bad).is_err(), "{bad}");
        }
    }

    /// The row, written group by group, holds in each place the column
    /// that [`TermSet::for_each_column`] names there, bit for bit (every
    /// group, lags, extras; a missing lag or extra gives NaN).
    #[test]
    fn rows_follow_the_column_table() {
        let dir = [21_000.0, -2_500.0, 44_000.0];
        let b = [20_000.0, -3_000.0, 45_000.0];
        let db = [1.5, -0.25, 0.75];
        let lagged = [[0.5, 0.125, -2.0], [3.0, -1.0, 0.25]];
        let extra = [[2.0, 9.0], [4.0, 3.0]];
        let bt = magnitude(dir);
        let e = dir.map(|d| d / bt);
        for spec in ["p3,i6,e9", "p3,i5,e8", "p3,i6,e9,bias", "i5,p3,bias,e8"] {
            for (lags, extras) in [
                (vec![], vec![]),
                (
                    vec![0.2, 0.7],
                    vec![ExtraTerm::new("a"), ExtraTerm::lagged("b", 0.3)],
                ),
            ] {
                let t = TermSet::parse(spec)
                    .unwrap()
                    .with_eddy_lags(&lags)
                    .unwrap()
                    .with_extras(&extras)
                    .unwrap();
                for (lagged, extra) in [(&lagged[..], &extra[..]), (&lagged[..1], &extra[..1])] {
                    let mut row = vec![0.0; t.n_columns()];
                    t.row_along(dir, b, db, lagged, extra, 5e4, &mut row);
                    let mut k = 0;
                    t.for_each_column(|c| {
                        let want = match c {
                            Column::Direction(i) => e[i],
                            Column::Product { i, source, j } => {
                                let s = match source {
                                    Source::Field => b[j],
                                    Source::Derivative => db[j],
                                    Source::Lagged(l) => lagged.get(l).map_or(f64::NAN, |g| g[j]),
                                };
                                product(e[i], s, 5e4)
                            }
                            Column::Bias => 1.0,
                            Column::Extra { i, k, lagged } => {
                                e[i] * extra.get(k).map_or(f64::NAN, |x| x[usize::from(lagged)])
                            }
                        };
                        assert_eq!(
                            row[k].to_bits(),
                            want.to_bits(),
                            "{spec} {lags:?} column {k} {c:?}"
                        );
                        k += 1;
                    });
                    assert_eq!(k, row.len());
                }
            }
        }
    }

    #[test]
    fn derivative_conventions() {
        let t = [0.0, 0.1, 0.2, 0.3];
        let x = [0.0, 1.0, 4.0, 9.0];
        assert_eq!(
            derivative(&x, &t, Convention::MagNav),
            vec![1.0, 2.0, 4.0, 5.0]
        );
        let p = derivative(&x, &t, Convention::Physical);
        assert!(
            (p[1] - 20.0).abs() < 1e-12
                && (p[0] - 10.0).abs() < 1e-12
                && (p[3] - 50.0).abs() < 1e-9
        );
    }

    proptest::proptest! {
        /// Any block of rows is the same bits as those rows of the whole
        /// series, under every convention and differencing, ends included.
        #[test]
        fn rows_of_a_derivative_are_the_whole_series_rows(
            x in proptest::collection::vec(-1e4f64..1e4, 0..40),
            cut in (0usize..40, 0usize..40),
        ) {
            let n = x.len();
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1 + (i % 3) as f64 * 1e-3).collect();
            let (a, b) = (cut.0.min(n), cut.1.min(n));
            let rows = a.min(b)..a.max(b);
            for convention in [Convention::MagNav, Convention::Physical] {
                for differencing in [Differencing::Centred, Differencing::Backward] {
                    let mut whole = Vec::new();
                    derivative_into(&x, &t, convention, differencing, &mut whole);
                    let mut part = vec![7.0; 5];
                    derivative_rows_into(&x, &t, convention, differencing, rows.clone(), &mut part);
                    let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                    proptest::prop_assert_eq!(bits(&part), bits(&whole[rows.clone()]));
                }
            }
        }
    }
}
