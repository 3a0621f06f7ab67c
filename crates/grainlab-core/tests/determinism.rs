//! Same input and thread count give the same bits; a saved and reloaded state
//! continues bitwise identically.
mod common;
use common::*;
use grainlab_core::Simulation;

fn sheared(threads: usize) -> Simulation {
    let mut sim = bench_packing(0.9, 0.2, threads);
    let mut cell = sim.cell.clone().unwrap();
    cell.velocity_gradient = [[-0.05, 0.0], [0.0, 0.05]];
    sim.set_cell(Some(cell)).unwrap();
    let mut p = sim.params;
    p.local_damping = 0.1;
    sim.set_params(p).unwrap();
    sim
}

fn fingerprint(sim: &Simulation) -> Vec<u64> {
    let p = &sim.particles;
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
    bits.extend(sim.neighbors.pairs.shear.iter().map(|s| s.to_bits()));
    bits
}

#[test]
fn two_runs_with_the_same_input_are_bitwise_identical() {
    for threads in [1, 2] {
        let mut a = sheared(threads);
        let mut b = sheared(threads);
        a.run(1500).unwrap();
        b.run(1500).unwrap();
        assert!(a.neighbors.build_count > 1);
        assert_eq!(fingerprint(&a), fingerprint(&b), "threads = {threads}");
    }
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
        assert_eq!(straight.time, resumed.time);
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

#[test]
fn a_state_indexing_what_it_does_not_hold_is_refused() {
    // The force kernels read particle arrays without bounds checks, trusting the
    // neighbour lists; a stale or edited state must be refused when loaded.
    let mut sim = bench_packing(0.5, 0.2, 1);
    sim.run(5).unwrap();
    let good = sim.to_bytes().unwrap();
    assert!(Simulation::from_bytes(&good).is_ok());
    let n = sim.particles.len() as u32;
    let cases: Vec<(&str, Box<dyn Fn(&mut Simulation)>)> = vec![
        (
            "a pair names a particle",
            Box::new(move |s| s.neighbors.pairs.j[0] = n + 7),
        ),
        (
            "pair arrays",
            Box::new(|s| {
                s.neighbors.pairs.shear.pop();
            }),
        ),
        (
            "contact model",
            Box::new(|s| s.neighbors.pairs.model[0] = u16::MAX),
        ),
        (
            "block ranges",
            Box::new(|s| s.neighbors.block_ranges[0].1 += 1),
        ),
        (
            "particle arrays",
            Box::new(|s| {
                s.particles.velocity.pop();
            }),
        ),
    ];
    for (what, edit) in cases {
        let mut broken = Simulation::from_bytes(&good).unwrap();
        edit(&mut broken);
        let err = Simulation::from_bytes(&broken.to_bytes().unwrap())
            .err()
            .unwrap_or_else(|| panic!("{what}: must be refused"));
        assert!(err.to_string().contains("inconsistent"), "{what}: {err}");
        // the same edit made in memory is refused by the next run, before any step
        let mut edited = Simulation::from_bytes(&good).unwrap();
        edit(&mut edited);
        let err = edited
            .run(1)
            .err()
            .unwrap_or_else(|| panic!("{what}: run must refuse"));
        assert!(err.to_string().contains("inconsistent"), "{what}: {err}");
    }
}
