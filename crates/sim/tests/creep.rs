//! A permanent moment that creeps (issue 21's long-flight case): the truth
//! of a flight with a creeping part differs from the same flight without
//! by the creeping part's dipole field times the hours flown, exactly, and
//! nothing else changes.

use aeromag_core::field::dipole::dipole_matrix;
use aeromag_sim::{ScenarioKind, Simulation, default_config_toml, simulate};
use nalgebra::Vector3;

fn col<'a>(s: &'a Simulation, name: &str) -> &'a [f64] {
    s.column(name).unwrap_or_else(|| panic!("no column {name}"))
}

#[test]
fn a_creeping_moment_adds_its_dipole_field_times_the_hours() {
    let base = default_config_toml(ScenarioKind::Survey).unwrap();
    // The first part (left engine at (1.0, −3.2, 0.2) m) gains
    // (20, −10, 5) A·m² per hour.
    let creep = [20.0, -10.0, 5.0];
    let crept = base.replacen(
        "permanent_creep_am2_per_h = [0.0, 0.0, 0.0]",
        "permanent_creep_am2_per_h = [20.0, -10.0, 5.0]",
        1,
    );
    assert_ne!(crept, base);
    assert!(base.contains("position_m = [1.0, -3.2, 0.2]"));
    let a = simulate(ScenarioKind::Survey, Some(&base), Some(3)).unwrap();
    let b = simulate(ScenarioKind::Survey, Some(&crept), Some(3)).unwrap();
    // The stinger sensor's offset from the part, and the field per hour, nT.
    let r = Vector3::new(-9.5, 0.0, -0.6) - Vector3::new(1.0, -3.2, 0.2);
    let per_h = dipole_matrix(&r) * Vector3::from(creep) * 1e9;
    let t = col(&a, "time");
    let hours = (t[t.len() - 1] - t[0]) / 3600.0;
    assert!(hours > 0.4, "{hours} h");
    for (axis, name) in ["true_interf_x", "true_interf_y", "true_interf_z"]
        .iter()
        .enumerate()
    {
        let (x, y) = (col(&a, name), col(&b, name));
        for k in (0..t.len()).step_by(997) {
            let want = per_h[axis] * (t[k] - t[0]) / 3600.0;
            assert!(
                (y[k] - x[k] - want).abs() < 1e-9 * per_h.norm().max(1.0),
                "{name} row {k}: {} vs {want}",
                y[k] - x[k]
            );
        }
    }
    // The permanent part of the scalar interference moves; the induced
    // part and the trajectory do not.
    let p = (col(&a, "true_interf_perm"), col(&b, "true_interf_perm"));
    let n = t.len() - 1;
    assert_eq!(p.0[0], p.1[0]);
    let e = Vector3::new(
        col(&a, "true_ext_x")[n],
        col(&a, "true_ext_y")[n],
        col(&a, "true_ext_z")[n],
    )
    .normalize();
    let want = e.dot(&per_h) * hours;
    assert!(want.abs() > 0.1, "{want} nT");
    assert!(
        (p.1[n] - p.0[n] - want).abs() < 1e-6,
        "{} vs {want} nT",
        p.1[n] - p.0[n]
    );
    assert_eq!(
        col(&a, "true_interf_induced"),
        col(&b, "true_interf_induced")
    );
    assert_eq!(col(&a, "lat"), col(&b, "lat"));
}
