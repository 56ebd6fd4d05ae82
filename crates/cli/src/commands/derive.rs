//! `aeromag derive`: a grid derived from a grid file — first vertical
//! derivative, upward continuation, or difference (library:
//! [`aeromag::map::derive`]).

use aeromag::core::error::fixed;
use aeromag::map::picture::MapPicture;
use aeromag::map::{GridProduct, derive};
use std::path::PathBuf;

/// Derive a grid from a grid file (GeoTIFF, ESRI ASCII, netCDF, GXF or a
/// Surfer .grd; the output's format follows its extension). Exactly one of
/// the products.
///
/// The vertical derivative and upward continuation are computed by FFT on
/// the grid made complete (blanks filled harmonically) and mirrored about
/// its edges; blanks stay blank. The filters need at least 2 × 2 nodes
/// and one value.
///
/// Input grids are checked (exit code 2, naming the file): NODATA and NaN
/// nodes are blank; an infinite value or one beyond float32's range
/// (±3.4e38: every grid format stores float32, and no field or gradient
/// comes near it) is an error naming its row (from the north) and column; the cell size must be 1e-6 to 1e6 m, node coordinates within
/// ±1e9 m, and the header may not declare more nodes than the file holds
/// (a GeoTIFF's strips must hold exactly the image its header declares).
/// Coordinates must be metres of a projected system (e.g. UTM): a grid
/// whose .prj, GeoTIFF keys or netCDF units declare degrees (a geographic
/// system) or feet is refused; netCDF coordinates in km are converted to m.
///
/// Examples:
///   aeromag derive --input mag.tif --vertical-derivative --out fvd.tif
///   aeromag derive --input mag.nc --upward 200 --out up200.nc
///   aeromag derive --input levelled.tif --minus truth.tif --out error.tif
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(group(clap::ArgGroup::new("product").required(true).multiple(false)))]
#[command(mut_arg("input", |a| a.value_name("GRID").help("Input grid file")))]
#[command(mut_arg("file", |a| a.value_name("GRID")))]
pub struct Args {
    #[command(flatten)]
    input: crate::input::InputFile,
    /// Output grid file; the format follows the extension, as `aeromag
    /// grid --out` (`NAME.grd(GRD)`: Oasis montaj's own grid).
    #[arg(long, value_name = "GRID")]
    out: PathBuf,
    /// First vertical derivative (z down), nT/m.
    #[arg(long, group = "product")]
    vertical_derivative: bool,
    /// Upward continuation by this height, m: from 1e-8 cell (lower
    /// heights change no value at float32 precision) to 10 times the
    /// grid's extent, max(columns, rows) × cell (higher ones leave only
    /// the grid's mean).
    #[arg(long, value_name = "M", group = "product", value_parser = crate::args::non_negative)]
    upward: Option<f64>,
    /// The input minus this grid (the same nodes in the same coordinate
    /// system, e.g. UTM zone, when both files record one; at least one
    /// node set in both).
    #[arg(long, value_name = "GRID", group = "product")]
    minus: Option<PathBuf>,
    /// Also draw the derived grid as a map, PNG (`.png`) or SVG (`.svg`):
    /// a derivative or difference in diverging colours centred on zero, a
    /// continued field in colour with shaded relief.
    #[arg(long, value_name = "MAP.png")]
    map: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_map(a.map.as_deref())?;
    crate::output::check_files(
        std::iter::once(a.out.as_path()).chain(a.map.as_deref()),
        &[a.input.path()],
    )?;
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
    let g = derive(a.input.path(), &product)?;
    let format = aeromag::grid::format::write_grid(&a.out, &g)?;
    let s = g.stats();
    println!(
        "{}: {} × {} nodes, {} not blank; mean {}, std {}, min {}, max {} {}",
        g.name,
        g.geometry.nx,
        g.geometry.ny,
        s.count,
        fixed(s.mean, 4),
        fixed(s.std, 4),
        fixed(s.min, 4),
        fixed(s.max, 4),
        g.unit
    );
    println!("wrote {}", a.out.display());
    if let Some(note) = aeromag::map::crs_not_written(format, &g) {
        eprintln!("{note}");
    }
    if let Some(path) = &a.map {
        let picture = match product {
            GridProduct::Upward(_) => MapPicture::field(&g),
            GridProduct::VerticalDerivative | GridProduct::Minus(_) => MapPicture::diverging(&g),
        };
        let format = picture.write(&g, path)?;
        println!("map: {} ({format:?})", path.display());
    }
    Ok(())
}
