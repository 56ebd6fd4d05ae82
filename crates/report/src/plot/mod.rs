//! Plots: line/step/scatter plots and heatmaps, rendered to SVG or PNG.
//!
//! The pipeline of every plot is the same: data are mapped into axis units
//! (`axis.rs`: identity or `log10`, undrawable values become gaps), view
//! ranges and nice ticks are chosen (`ticks.rs`), lines are clipped to the
//! view (`clip.rs`) and decimated to the pixel grid (`decimate.rs`), and the
//! result is drawn with plotters through one backend-generic routine
//! (`canvas.rs`) that both the SVG and the bitmap backend run.

mod axis;
mod bitmap;
mod canvas;
mod clip;
pub mod colormap;
mod decimate;
pub mod heatmap;
pub mod line;
mod ticks;
