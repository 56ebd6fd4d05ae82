//! `aeromag derive`: a grid derived from a grid file — first vertical
//! derivative, upward continuation, or difference (library:
//! [`aeromag::map::derive`]).

use aeromag::map::{GridProduct, derive};
use std::path::PathBuf;

/// Derive a grid from a grid file (GeoTIFF, ESRI ASCII or netCDF; the
/// output's format follows its extension). Exactly one of the products.
///
/// The vertical derivative and upward continuation are computed by FFT on
/// the grid made complete (blanks filled harmonically) and mirrored about
/// its edges; blanks stay blank.
///
/// Examples:
///   aeromag derive --input mag.tif --vertical-derivative --out fvd.tif
///   aeromag derive --input mag.nc --upward 200 --out up200.nc
///   aeromag derive --input levelled.tif --minus truth.tif --out error.tif
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(group(clap::ArgGroup::new("product").required(true).multiple(false)))]
pub struct Args {
    /// Input grid file.
    #[arg(long, short = 'i', value_name = "GRID")]
    input: PathBuf,
    /// Output grid file.
    #[arg(long, value_name = "GRID")]
    out: PathBuf,
    /// First vertical derivative (z down), nT/m.
    #[arg(long, group = "product")]
    vertical_derivative: bool,
    /// Upward continuation by this height, m.
    #[arg(long, value_name = "M", group = "product", value_parser = crate::args::non_negative)]
    upward: Option<f64>,
    /// The input minus this grid (the same nodes).
    #[arg(long, value_name = "GRID", group = "product")]
    minus: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_files(std::iter::once(a.out.as_path()))?;
    let product = match (a.vertical_derivative, a.upward, &a.minus) {
        (true, _, _) => GridProduct::VerticalDerivative,
        (_, Some(h), _) => GridProduct::Upward(h),
        (_, _, Some(other)) => GridProduct::Minus(other.clone()),
        _ => {
            return Err(crate::exit::bad_input!(
                "choose --vertical-derivative, --upward or --minus"
            ));
        }
    };
    let g = derive(&a.input, &product)?;
    aeromag::grid::format::write_grid(&a.out, &g)?;
    let s = g.stats();
    println!(
        "{}: {} × {} nodes, {} not blank; mean {:.4}, std {:.4}, min {:.4}, max {:.4} {}",
        g.name, g.geometry.nx, g.geometry.ny, s.count, s.mean, s.std, s.min, s.max, g.unit
    );
    println!("wrote {}", a.out.display());
    Ok(())
}
