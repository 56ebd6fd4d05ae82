//! `aeromag grid`: a survey column on a grid by minimum curvature with
//! tension, blanked away from the lines, written as GeoTIFF, ESRI ASCII,
//! netCDF or GXF (library: [`aeromag::map::grid_flight`]).

use crate::args;
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::grid::GridGeometry;
use aeromag::grid::projection::UtmZone;
use aeromag::map::gridding::GridMethod;
use aeromag::map::picture::{MapPicture, tracks};
use aeromag::map::{GridOptions, grid_flight};
use std::path::PathBuf;

/// Grid a levelled survey (or any column of it) and write the grid.
///
/// Latitude and longitude are projected to UTM (the zone of the data, or
/// --utm-zone); positions already projected (X, Y) are taken as they are
/// (--xy); rows on lines (line label ≠ 0) are gridded. Defaults
/// follow the lines: the cell is a quarter of the line spacing, nodes
/// farther than one line spacing from the data are blank. Rows whose
/// position jumps off the track and back faster than 1000 m/s (a GPS
/// dropout written as 0) are left out with a warning that names them.
///
/// Examples:
///   aeromag grid -i levelled.csv --cell 50 --out mag.tif
///   aeromag grid -i levelled.csv --column mag_comp --out comp.nc --tension 0.35
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Output grid; the format follows the extension: `.tif` (GeoTIFF,
    /// float32), `.asc` (ESRI ASCII grid, with a `.prj`), `.nc` / `.grd`
    /// (netCDF, COARDS, as GMT reads and writes it; not Surfer's or
    /// Geosoft's binary .grd), `.gxf` (GXF-3, Geosoft's Grid eXchange
    /// File, as Oasis montaj and GDAL read it) or `NAME.grd(GRD)` (Oasis
    /// montaj's decoration: its own binary grid, written to NAME.grd,
    /// without the coordinate system, which Oasis keeps in a .gi file).
    #[arg(long, value_name = "GRID")]
    out: PathBuf,
    /// Column to grid (default: the most processed magnetic column of the
    /// file, compensated first, names in any case: mag_comp_level_mlev,
    /// mag_<k>_comp_level_mlev, mag_level_mlev, mag_comp_level, …,
    /// mag_comp, mag_<k>_comp (the first sensor's in the file), mag; an
    /// uncompensated column taken so is warned of [uncompensated-default]).
    #[arg(long)]
    column: Option<String>,
    /// Cell size (node spacing), m, 1e-6 to 1e6 (default: a quarter of
    /// the line spacing, rounded down to 1, 2, 2.5 or 5 × 10ᵏ m). A cell
    /// finer than 0.02 line spacings is warned of [fine-cell].
    #[arg(long, value_parser = args::positive)]
    cell: Option<f64>,
    #[command(flatten)]
    min_curvature: args::MinCurvatureArgs,
    /// Gridding method.
    #[arg(long, value_enum, default_value_t = GridMethod::MinCurvature)]
    method: GridMethod,
    /// The grid's extent in the projected coordinates, m: the western and
    /// eastern columns and the southern and northern rows of nodes
    /// (default: the data's extent, nodes on multiples of the cell).
    #[arg(long, value_name = "XMIN,XMAX,YMIN,YMAX", allow_hyphen_values = true,
          value_parser = extent)]
    extent: Option<[f64; 4]>,
    /// Blank nodes farther than this from the data, m (default: the line
    /// spacing).
    #[arg(long, value_parser = args::positive)]
    blanking: Option<f64>,
    /// UTM zone, e.g. `37N`, `56S` or `EPSG:32637` (default: the zone of
    /// the data's median longitude); with projected positions (--xy), the
    /// zone they are in.
    #[arg(long, value_name = "ZONE", value_parser = args::utm_zone)]
    utm_zone: Option<UtmZone>,
    /// Positions already projected: the columns EASTING,NORTHING (m),
    /// e.g. `X,Y`, in place of lat/lon (default: lat/lon; in a file
    /// without them, the first of x,y, easting,northing, utm_x,utm_y,
    /// utm-x,utm-y, utm_easting,utm_northing, any case). Their UTM zone, when given
    /// with --utm-zone, is the grid's coordinate system; without it the
    /// grid has none [no-crs].
    #[arg(long, value_name = "EASTING,NORTHING", value_parser = args::projected_columns)]
    xy: Option<aeromag::map::ProjectedColumns>,
    /// Sensor lever arm X,Y,Z from the navigation point, body frame, m:
    /// grid at the sensor's positions (needs roll, pitch, yaw and alt).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz)]
    lever_arm: Option<[f64; 3]>,
    /// Also draw the grid as a map, PNG (`.png`) or SVG (`.svg`): colour
    /// with shaded relief, the flight lines over it, easting and northing
    /// in km.
    #[arg(long, value_name = "MAP.png")]
    map: Option<PathBuf>,
}

fn extent(s: &str) -> Result<[f64; 4], String> {
    let v = args::numbers(s, 4)?;
    Ok([v[0], v[1], v[2], v[3]])
}

pub fn run(a: Args) -> anyhow::Result<()> {
    // The format by the extension, then the path: both before the work.
    aeromag::map::SurveyGrid::format_of(&a.out)?;
    crate::output::check_map(a.map.as_deref())?;
    crate::output::check_files(
        std::iter::once(a.out.as_path()).chain(a.map.as_deref()),
        &[a.input.path()],
    )?;
    let geometry = match (&a.extent, a.cell) {
        (Some(e), Some(cell)) => Some(GridGeometry::covering(e[0], e[1], e[2], e[3], cell)?),
        (Some(_), None) => return Err(crate::exit::bad_input!("--extent needs --cell")),
        (None, _) => None,
    };
    // The canonical columns and the magnetic ones it may grid: a wide
    // survey file's other fields are not parsed.
    let wanted = aeromag::flight::default_column_fields(&aeromag::map::PROCESSING_STAGES);
    let mut extra: Vec<&str> = wanted.iter().map(String::as_str).collect();
    extra.extend(a.column.as_deref());
    // Projected positions, named or those a file without lat/lon may have.
    match &a.xy {
        Some(xy) => extra.extend([xy.easting.as_str(), xy.northing.as_str()]),
        None => extra.extend(aeromag::map::PROJECTED_NAMES.iter().flatten()),
    }
    let flight = a.input.load_canonical(&extra)?;
    let opts = GridOptions {
        geometry,
        column: a.column.clone(),
        cell_m: a.cell,
        blanking_m: a.blanking,
        zone: a.utm_zone,
        projected: a.xy.clone(),
        lever_arm_m: a.lever_arm,
        method: a.method,
        min_curvature: a.min_curvature.settings(),
    };
    let g = grid_flight(&flight, &opts, &mut Bars::new())?;
    let format = g.write(&a.out)?;
    let geo = &g.grid.geometry;
    println!("gridded {} ({} rows on lines)", g.column, g.rows_used);
    if let Some(l) = &g.survey.lines {
        println!(
            "lines: {} traverse lines at {:.1}° from grid north, spacing {:.1} m ({} other lines)",
            l.traverse_lines, l.direction_deg, l.spacing_m, l.other_lines
        );
    }
    println!(
        "grid: {} × {} nodes, cell {} m, {}, x {:.1}–{:.1} m, y {:.1}–{:.1} m",
        geo.nx,
        geo.ny,
        geo.cell,
        g.grid
            .crs
            .map_or("no coordinate system".into(), |c| format!(
                "{} (EPSG:{})",
                c.name(),
                c.epsg()
            )),
        geo.x0,
        geo.x_max(),
        geo.y0,
        geo.y_max()
    );
    match a.method {
        // No levels: data that are exactly a plane need no sweep.
        GridMethod::MinCurvature => println!(
            "minimum curvature, tension {}: {} nodes hold data, {} sweeps on the final grid, {}",
            opts.min_curvature.tension,
            g.report.constrained_nodes,
            g.report.levels.last().map_or(0, |l| l.iterations),
            if g.report.converged {
                "converged"
            } else {
                "NOT converged"
            }
        ),
        GridMethod::Bidirectional => println!(
            "bi-directional: along the lines, then across them (Akima); {} nodes hold data",
            g.report.constrained_nodes
        ),
    }
    println!(
        "blanking beyond {:.1} m: {} of {} nodes blank",
        g.blanking_m,
        g.blanked_nodes,
        geo.len()
    );
    let s = g.grid.stats();
    println!(
        "values: mean {:.3}, std {:.3}, min {:.3}, max {:.3} {}",
        s.mean, s.std, s.min, s.max, g.grid.unit
    );
    println!("wrote {} ({format:?})", a.out.display());
    if let Some(note) = aeromag::map::crs_not_written(format, &g.grid) {
        eprintln!("{note}");
    }
    if let Some(path) = &a.map {
        // A point of each line every so many rows: at most about 50 000.
        let step = (g.survey.x.len() / 50_000).max(1);
        let picture = MapPicture::field(&g.grid).with_tracks(tracks(&g.survey, step));
        let format = picture.write(&g.grid, path)?;
        println!("map: {} ({format:?})", path.display());
    }
    Ok(())
}
