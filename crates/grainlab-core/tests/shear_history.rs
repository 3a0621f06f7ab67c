//! The shear springs count every tangential displacement once: none on a step
//! that starts from full-step velocities, the last step's exactly once when
//! velocities or positions are set between steps (docs/contact-law.md).
mod common;
use common::*;
use grainlab_core::Simulation;

/// Every spring of the simulation: contacts, wall contacts, bonds (internal order).
fn springs(sim: &Simulation) -> Vec<f64> {
    let mut all = sim.neighbors().pairs.history.shear_springs();
    all.extend(sim.neighbors().wall_pairs.history.shear_springs());
    all.extend(sim.bonds().list.iter().map(|b| b.shear));
    all
}

#[test]
fn the_first_step_from_full_step_velocities_adds_no_shear() {
    // moving, spinning, overlapping disks against walls and in bonds: no
    // displacement has happened yet, so the first force evaluation leaves every
    // spring at zero, and the second one (after a real displacement) does not
    let mut sim = boxed_packing(16, 0.5, 3, 1);
    assert!(!sim.shear_increment_pending());
    sim.run(1).unwrap();
    let m = sim.measurements();
    assert!(m.contact_count > 150 && m.wall_contact_count > 20, "{m:?}");
    assert!(springs(&sim).iter().all(|&s| s == 0.0));
    assert!(sim.shear_increment_pending());
    sim.run(1).unwrap();
    let nonzero = |v: &[f64]| v.iter().filter(|&&s| s != 0.0).count();
    assert!(nonzero(&sim.neighbors().pairs.history.shear_springs()) > 150);
    assert!(nonzero(&sim.neighbors().wall_pairs.history.shear_springs()) > 20);
    assert_eq!(
        nonzero(&sim.bonds().list.iter().map(|b| b.shear).collect::<Vec<_>>()),
        15
    );
}

#[test]
fn velocities_set_between_steps_count_the_last_displacement_once() {
    let mut straight = boxed_packing(16, 0.5, 4, 1);
    straight.run(40).unwrap();
    let mut changed = Simulation::from_bytes(&straight.to_bytes().unwrap()).unwrap();
    // the next step adds the displacement of step 40 at the half-step velocities
    straight.run(1).unwrap();
    let expected = springs(&straight);
    // setting velocities first adds that same displacement, at the same velocities ...
    let p = changed.particles();
    let v: Vec<[f64; 2]> = p
        .velocity
        .iter()
        .map(|v| [-0.5 * v[0], 2.0 * v[1]])
        .collect();
    let w: Vec<f64> = p.angular_velocity.iter().map(|w| -w).collect();
    let (v, w) = (changed.to_external(&v), changed.to_external(&w));
    changed.set_velocities(&v).unwrap();
    changed.set_angular_velocities(&w).unwrap();
    assert!(!changed.shear_increment_pending());
    assert_eq!(springs(&changed), expected);
    // ... and the step from the new full-step velocities adds nothing more
    changed.run(1).unwrap();
    assert_eq!(springs(&changed), expected);
    // from then on the new velocities displace the contacts as usual
    changed.run(1).unwrap();
    assert_ne!(springs(&changed), expected);
}

#[test]
fn positions_set_between_steps_are_a_jump_not_a_displacement() {
    let mut straight = boxed_packing(16, 0.5, 5, 1);
    straight.run(40).unwrap();
    let mut moved = Simulation::from_bytes(&straight.to_bytes().unwrap()).unwrap();
    straight.run(1).unwrap();
    let expected = springs(&straight);
    // a tiny jump of every disk: the springs take the last step's displacement
    // first and nothing from the jump
    let mut rng = Rng::new(9);
    let mut x = moved.to_external(&moved.particles().position);
    for xk in x.iter_mut() {
        *xk = [
            xk[0] + rng.uniform(-1e-9, 1e-9),
            xk[1] + rng.uniform(-1e-9, 1e-9),
        ];
    }
    moved.set_positions(&x).unwrap();
    assert_eq!(springs(&moved), expected);
    // the next step adds no increment (only a cap where the overlap shrank)
    moved.run(1).unwrap();
    let (after, before) = (by_pair(&moved), by_pair(&straight));
    assert_eq!(after.len(), before.len());
    let mut capped = 0;
    for (key, &(a, sliding)) in &after {
        let b = before[key].0;
        if a != b {
            capped += 1;
            assert!(sliding && a.abs() < b.abs() * (1.0 + 1e-9), "{a} vs {b}");
        }
    }
    assert!(capped < after.len() / 4, "{capped} of {}", after.len());
}

/// The touching pairs' springs and sliding flags by external `(i, j)`.
fn by_pair(sim: &Simulation) -> std::collections::HashMap<(usize, usize), (f64, bool)> {
    let p = &sim.neighbors().pairs;
    (0..p.len())
        .filter(|&k| p.history.shear_spring(k) != 0.0)
        .map(|k| {
            let (i, j) = (
                sim.external_index(p.i[k] as usize),
                sim.external_index(p.j[k] as usize),
            );
            (
                (i.min(j), i.max(j)),
                (p.history.shear_spring(k), p.history.sliding[k]),
            )
        })
        .collect()
}
