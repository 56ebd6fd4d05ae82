//! Helpers shared by the library's integration tests.

use aeromag::FlightTable;
use aeromag::flight::Flight;

/// `flight` with its latitude and longitude replaced by the columns `X`
/// and `Y` of `x` and `y`: positions already projected, as a Geosoft XYZ
/// export has them.
pub fn with_projected_positions(flight: &Flight, x: &[f64], y: &[f64]) -> Flight {
    let mut table = FlightTable::new();
    for name in flight.table().column_names() {
        if !["lat", "lon"].contains(&name) {
            let v = flight.table().column(name).unwrap().to_vec();
            table.add_column(name, v).unwrap();
        }
    }
    table.add_column("X", x.to_vec()).unwrap();
    table.add_column("Y", y.to_vec()).unwrap();
    Flight::from_table(table).unwrap()
}
