//! The Verlet lists never miss a contact: compared with brute force on random
//! configurations with a wide size spread, fast particles, periodic cells,
//! an imposed deformation, and walls.
mod common;
use common::*;
use grainlab_core::vec2::{add, dot, sub};
use grainlab_core::{
    ContactModel, Particles, PeriodicCell, Simulation, StepParameters, Wall, WallShape,
};
use std::collections::BTreeSet;

/// Contacts by brute force over all pairs and all images within one cell, as
/// external index pairs.
fn brute_force(sim: &Simulation) -> BTreeSet<(u32, u32)> {
    let p = &sim.particles();
    let mut out = BTreeSet::new();
    let images: Vec<[i8; 2]> = match sim.cell() {
        Some(c) => {
            let sx: Vec<i8> = if c.periodic[0] {
                vec![-1, 0, 1]
            } else {
                vec![0]
            };
            let sy: Vec<i8> = if c.periodic[1] {
                vec![-1, 0, 1]
            } else {
                vec![0]
            };
            sx.iter()
                .flat_map(|&a| sy.iter().map(move |&b| [a, b]))
                .collect()
        }
        None => vec![[0, 0]],
    };
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            for &s in &images {
                let off = sim.cell().map_or([0.0; 2], |c| c.image_offset(s));
                let d = sub(add(p.position[j], off), p.position[i]);
                let reach = p.radius[i] + p.radius[j];
                if dot(d, d) < reach * reach {
                    // the engine reports external (user) indices
                    let (a, b) = (sim.external_index(i) as u32, sim.external_index(j) as u32);
                    out.insert((a.min(b), a.max(b)));
                }
            }
        }
    }
    out
}

fn engine_contacts(sim: &mut Simulation) -> BTreeSet<(u32, u32)> {
    let c = sim.contacts().unwrap();
    c.i.iter().zip(&c.j).map(|(&i, &j)| (i, j)).collect()
}

/// Random disks with radii spread `r_min..r_max` (ratio 10) in a box, random fast velocities.
fn random_sim(seed: u64, periodic: bool, deform: bool, threads: usize) -> Simulation {
    let mut rng = Rng::new(seed);
    let l = 0.05;
    let n = 300;
    let (mut pos, mut rad) = (Vec::new(), Vec::new());
    for _ in 0..n {
        pos.push([rng.uniform(0.0, l), rng.uniform(0.0, l)]);
        // a few large disks among many small ones
        rad.push(if rng.uniform(0.0, 1.0) < 0.05 {
            rng.uniform(2e-3, 3e-3)
        } else {
            rng.uniform(3e-4, 8e-4)
        });
    }
    let particles = Particles::new(pos, rad, vec![DENSITY]).unwrap();
    // soft contacts so that fast particles may pass deep into one another without blowing up
    let mut sim = Simulation::new(
        particles,
        ContactModel::linear(1.0e3, 1.0e3, 0.3),
        1e-5,
        threads,
    )
    .unwrap();
    sim.set_params(StepParameters {
        time_step: 1e-5,
        local_damping: 0.0,
        gravity: [0.0; 2],
        max_overlap_ratio: 1e9,
    })
    .unwrap();
    if periodic {
        let mut cell = PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap();
        if deform {
            cell.velocity_gradient = [[-20.0, 15.0], [0.0, 20.0]];
        }
        sim.set_cell(Some(cell)).unwrap();
    }
    // up to 5 m/s: 50 um per step, a large fraction of the small radii and of the skin
    let velocity: Vec<[f64; 2]> = (0..n)
        .map(|_| [rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0)])
        .collect();
    sim.set_velocities(&velocity).unwrap();
    sim
}

fn check_over_time(mut sim: Simulation, steps: usize) {
    let mut checked = 0;
    for step in 0..steps {
        sim.run(1).unwrap();
        let expected = brute_force(&sim);
        let got = engine_contacts(&mut sim);
        assert_eq!(
            got, expected,
            "step {step}: engine and brute force disagree"
        );
        checked += expected.len();
    }
    assert!(checked > 100, "too few contacts to be a test: {checked}");
    assert!(sim.neighbors().build_count > 3, "lists were never rebuilt");
}

#[test]
fn open_domain_matches_brute_force() {
    for seed in 0..3 {
        check_over_time(random_sim(seed, false, false, 1), 200);
    }
}

#[test]
fn periodic_cell_matches_brute_force() {
    for seed in 10..13 {
        check_over_time(random_sim(seed, true, false, 2), 200);
    }
}

#[test]
fn deforming_periodic_cell_matches_brute_force() {
    for seed in 20..22 {
        check_over_time(random_sim(seed, true, true, 2), 200);
    }
}

#[test]
fn moving_walls_never_miss_a_contact() {
    let mut sim = random_sim(30, false, false, 1);
    let wall = Wall::new(
        WallShape::Segment {
            a: [0.0, -0.01],
            b: [0.0, 0.06],
        },
        1,
    )
    .unwrap();
    let id = sim.add_wall(wall);
    sim.set_wall_velocity(id, [40.0, 0.0]).unwrap(); // sweeps across the box
    for step in 0..120 {
        sim.run(1).unwrap();
        let wc = sim.wall_contacts().unwrap();
        let got: BTreeSet<u32> = wc.particle.iter().copied().collect();
        let p = &sim.particles();
        let expected: BTreeSet<u32> = (0..p.len())
            .filter(|&q| {
                sim.walls()[id]
                    .disk_contact(p.position[q], p.radius[q])
                    .overlap
                    > 0.0
            })
            .map(|q| sim.external_index(q) as u32)
            .collect();
        assert_eq!(got, expected, "step {step}");
    }
}
