//! Same input gives the same bits, whatever the thread count; a saved and
//! reloaded state continues bitwise identically, on any thread count.
mod common;
use common::*;
use grainlab_core::{Simulation, WallControl};

fn sheared(threads: usize) -> Simulation {
    let mut sim = bench_packing(0.9, 0.2, threads);
    let mut cell = sim.cell().cloned().unwrap();
    cell.velocity_gradient = [[-0.05, 0.0], [0.0, 0.05]];
    sim.set_cell(Some(cell)).unwrap();
    let mut p = sim.params();
    p.local_damping = 0.1;
    sim.set_params(p).unwrap();
    sim
}

fn fingerprint(sim: &Simulation) -> Vec<u64> {
    let p = &sim.particles();
    let mut bits = Vec::new();
    for k in 0..p.len() {
        bits.extend(
            [
                p.position[k][0],
                p.position[k][1],
                p.velocity[k][0],
                p.velocity[k][1],
                p.angular_velocity[k],
                p.rotation[k],
            ]
            .map(f64::to_bits),
        );
    }
    bits.extend(
        sim.neighbors()
            .pairs
            .history
            .shear_springs()
            .iter()
            .map(|s| s.to_bits()),
    );
    bits
}

#[test]
fn two_runs_with_the_same_input_are_bitwise_identical() {
    for threads in [1, 2] {
        let mut a = sheared(threads);
        let mut b = sheared(threads);
        a.run(1500).unwrap();
        b.run(1500).unwrap();
        assert!(a.neighbors().build_count > 1);
        assert_eq!(fingerprint(&a), fingerprint(&b), "threads = {threads}");
    }
}

/// The box of `boxed_packing` (3,600 disks, so the parallel path is taken) with
/// its top wall shearing and compressing, the left wall replaced by the bonded
/// chain under a follower pressure: a membrane-like boundary.
fn sheared_box(threads: usize) -> Simulation {
    let n_side = 60;
    let mut sim = boxed_packing(n_side, 0.5, 11, threads);
    sim.set_wall_velocity(2, [0.02, -0.002]).unwrap();
    sim.set_wall_active(3, false).unwrap();
    let chain: Vec<usize> = (0..n_side).collect();
    sim.add_pressure_chain(&chain, 2.0e5, Some(0), Some(2))
        .unwrap();
    assert!(matches!(sim.walls()[2].control, WallControl::Velocity));
    sim
}

/// Everything a step leaves behind: particle state, springs, the reported
/// contact and wall forces, the walls' forces and the energy ledger.
fn full_fingerprint(sim: &mut Simulation) -> Vec<u64> {
    let mut bits = Vec::new();
    let p = &sim.particles();
    for (x, v) in sim
        .to_external(&p.position)
        .iter()
        .zip(sim.to_external(&p.velocity))
    {
        bits.extend([x[0], x[1], v[0], v[1]].map(f64::to_bits));
    }
    bits.extend(
        sim.to_external(&p.angular_velocity)
            .iter()
            .map(|w| w.to_bits()),
    );
    bits.extend(
        sim.to_external(&p.force)
            .iter()
            .flat_map(|f| f.map(f64::to_bits)),
    );
    bits.extend(contact_list_bits(sim));
    let w = sim.wall_contacts().unwrap();
    bits.extend(w.particle.iter().map(|&k| k as u64));
    bits.extend(
        w.normal_force
            .iter()
            .chain(&w.shear_force)
            .map(|f| f.to_bits()),
    );
    for wall in sim.walls() {
        bits.extend(wall.force.map(f64::to_bits));
    }
    let e = sim.energy();
    bits.extend(
        [
            e.kinetic,
            e.elastic,
            e.friction_dissipated,
            e.damping_dissipated,
            e.wall_work,
            e.boundary_work,
        ]
        .map(f64::to_bits),
    );
    bits
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    // a sheared frictional box with walls, a bonded chain and a follower pressure,
    // and the sheared periodic bench packing: 1, 2, 3 and 4 threads, the same bits
    let mut reference: Option<(Vec<u64>, Vec<u64>)> = None;
    for threads in [1, 2, 3, 4] {
        let mut walled = sheared_box(threads);
        walled.run(400).unwrap();
        assert!(walled.neighbors().build_count > 1 && walled.neighbors().stripe_ranges.len() > 1);
        assert!(walled.measurements().wall_contact_count > 50);
        let mut periodic = sheared(threads);
        periodic.run(400).unwrap();
        let now = (
            full_fingerprint(&mut walled),
            full_fingerprint(&mut periodic),
        );
        match &reference {
            None => reference = Some(now),
            Some(r) => {
                assert!(
                    r.0 == now.0,
                    "walled box: threads = {threads} differs from 1"
                );
                assert!(
                    r.1 == now.1,
                    "periodic packing: threads = {threads} differs from 1"
                );
            }
        }
    }
}

#[test]
fn the_thread_count_can_change_mid_run() {
    let mut straight = sheared_box(2);
    straight.run(300).unwrap();
    let mut switched = sheared_box(1);
    switched.run(100).unwrap();
    switched.set_threads(3).unwrap();
    switched.run(100).unwrap();
    let mut resumed = Simulation::from_bytes(&switched.to_bytes().unwrap()).unwrap();
    resumed.set_threads(2).unwrap();
    resumed.run(100).unwrap();
    assert!(full_fingerprint(&mut straight) == full_fingerprint(&mut resumed));
}

#[test]
fn saved_state_continues_bitwise_identically() {
    for threads in [1, 2] {
        let mut straight = sheared(threads);
        straight.run(800).unwrap();
        let bytes = straight.to_bytes().unwrap();
        straight.run(700).unwrap();
        let mut resumed = Simulation::from_bytes(&bytes).unwrap();
        assert_eq!(resumed.threads(), threads);
        resumed.run(700).unwrap();
        assert_eq!(
            fingerprint(&straight),
            fingerprint(&resumed),
            "threads = {threads}"
        );
        assert_eq!(straight.energy(), resumed.energy());
        assert_eq!(straight.time(), resumed.time());
    }
}

#[test]
fn a_garbage_state_is_refused_with_a_clear_error() {
    let err = Simulation::from_bytes(b"not a state")
        .err()
        .expect("must fail");
    assert!(
        err.to_string().contains("not a grainlab engine state"),
        "{err}"
    );
}
