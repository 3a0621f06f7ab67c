//! Golden trajectories: representative systems run for thousands of steps must
//! end in exactly the bits recorded from the engine when these values were
//! written. Any change to the engine's arithmetic, its order of summation, its
//! renumbering or its neighbour-rebuild cadence changes these hashes; a change
//! meant to be invisible (a faster kernel, a restructuring) must keep them.
//!
//! Each system runs on 1 and 2 threads (the results do not depend on the thread
//! count, `determinism.rs`). The hash covers, in external particle order, the
//! positions, velocities, rotations and angular velocities, every shear spring
//! (particle pairs, wall pairs and bonds, keyed by their external indices), the
//! walls' positions, velocities and forces, the energy ledger and the clock.
mod common;
use common::*;
use grainlab_core::cement::{CementKind, CementSpec};
use grainlab_core::{
    ContactModel, Particles, ServoControl, Simulation, StepParameters, Wall, WallControl, WallShape,
};

/// FNV-1a over 64-bit words.
struct Hash(u64);

impl Hash {
    fn new() -> Self {
        Hash(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u64) {
        for byte in w.to_le_bytes() {
            self.0 ^= byte as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn f64(&mut self, x: f64) {
        self.word(x.to_bits());
    }
}

/// The hash of everything the trajectory consists of (see the module doc).
fn trajectory_hash(sim: &Simulation) -> u64 {
    let mut h = Hash::new();
    let p = sim.particles();
    for x in sim.to_external(&p.position) {
        h.f64(x[0]);
        h.f64(x[1]);
    }
    for v in sim.to_external(&p.velocity) {
        h.f64(v[0]);
        h.f64(v[1]);
    }
    for r in sim.to_external(&p.rotation) {
        h.f64(r);
    }
    for w in sim.to_external(&p.angular_velocity) {
        h.f64(w);
    }
    let ext = |k: u32| sim.external_index(k as usize) as u64;
    let pairs = &sim.neighbors().pairs;
    let mut springs: Vec<(u64, u64, i8, i8, u64)> = (0..pairs.len())
        .filter(|&k| pairs.history.shear_spring(k) != 0.0)
        .map(|k| {
            let (a, b) = (ext(pairs.i[k]), ext(pairs.j[k]));
            let s = pairs.shift[k];
            // the same pair seen from the other particle has the opposite image
            let (a, b, s) = if a < b {
                (a, b, s)
            } else {
                (b, a, [-s[0], -s[1]])
            };
            (a, b, s[0], s[1], pairs.history.shear_spring(k).to_bits())
        })
        .collect();
    springs.sort_unstable();
    h.word(springs.len() as u64);
    for (a, b, s0, s1, bits) in springs {
        h.word(a);
        h.word(b);
        h.word(s0 as u64);
        h.word(s1 as u64);
        h.word(bits);
    }
    let wp = &sim.neighbors().wall_pairs;
    let mut wall_springs: Vec<(u32, u64, u64)> = (0..wp.wall.len())
        .filter(|&k| wp.history.shear_spring(k) != 0.0)
        .map(|k| {
            (
                wp.wall[k],
                ext(wp.particle[k]),
                wp.history.shear_spring(k).to_bits(),
            )
        })
        .collect();
    wall_springs.sort_unstable();
    h.word(wall_springs.len() as u64);
    for (w, q, bits) in wall_springs {
        h.word(w as u64);
        h.word(q);
        h.word(bits);
    }
    for b in &sim.bonds().list {
        h.word(ext(b.i));
        h.word(ext(b.j));
        h.f64(b.shear);
    }
    // the cement bonds' springs and the breaks (nothing for an uncemented system)
    for b in &sim.cement().bonds {
        h.word(ext(b.i));
        h.word(ext(b.j));
        h.f64(b.shear);
        h.f64(b.moment);
    }
    for b in &sim.cement().breaks {
        h.word(b.step);
        h.word(b.i as u64);
        h.word(b.j as u64);
        h.word(b.mode as u64);
        for x in [
            b.energy,
            b.position[0],
            b.position[1],
            b.normal[0],
            b.normal[1],
        ] {
            h.f64(x);
        }
        for x in [b.normal_force, b.shear_force, b.moment] {
            h.f64(x);
        }
    }
    if !sim.cement().bonds.is_empty() || !sim.cement().breaks.is_empty() {
        h.f64(sim.energy().bond_released);
    }
    for wall in sim.walls() {
        h.f64(wall.displacement[0]);
        h.f64(wall.displacement[1]);
        h.f64(wall.velocity[0]);
        h.f64(wall.velocity[1]);
        h.f64(wall.force[0]);
        h.f64(wall.force[1]);
    }
    let e = sim.energy();
    for x in [
        e.kinetic,
        e.elastic,
        e.friction_dissipated,
        e.viscous_dissipated,
        e.damping_dissipated,
        e.wall_work,
        e.external_work,
        e.boundary_work,
        sim.time(),
    ] {
        h.f64(x);
    }
    h.word(sim.step_count());
    h.word(sim.neighbors().build_count);
    h.0
}

/// `build` run `steps` steps (in blocks of `block`, each call's last step
/// measured) on 1 and 2 threads, with the vector kernels (where the processor
/// can) and the scalar ones: every run must give `expected`, and the contact
/// lists of both must be the same bits.
fn check(
    name: &str,
    build: impl Fn(usize) -> Simulation,
    steps: u64,
    block: u64,
    expected: u64,
) -> Simulation {
    let mut last = None;
    for threads in [1, 2] {
        let mut lists = Vec::new();
        for vector in [true, false] {
            let mut sim = build(threads);
            let used = sim.set_simd(vector);
            let mut done = 0;
            while done < steps {
                let n = block.min(steps - done);
                sim.run(n).unwrap();
                done += n;
            }
            assert!(sim.neighbors().build_count > 1, "{name}: no rebuild");
            let got = trajectory_hash(&sim);
            assert!(
                got == expected,
                "{name}, {threads} thread(s), vector kernels {used}: trajectory hash \
                 {got:#018x}, recorded {expected:#018x}"
            );
            lists.push(contact_list_bits(&mut sim));
            last = Some(sim);
        }
        assert!(
            lists[0] == lists[1],
            "{name}: the contact lists of the two loops differ"
        );
    }
    last.unwrap()
}

/// 3,600 disks in four walls, the top and right ones servo-controlled to a
/// stress above the packing's, the first column bonded.
fn servo_box(threads: usize) -> Simulation {
    let mut sim = boxed_packing(60, 0.5, 5, threads);
    let l = 60.0e-3;
    for id in [1, 2] {
        let servo = ServoControl {
            target_stress: 4.0e5,
            loaded_length: l,
            relaxation: 0.5,
            max_speed: 0.05,
        };
        sim.set_wall_control(id, WallControl::Servo(servo)).unwrap();
    }
    sim
}

/// The servo box with its left wall replaced by the bonded first column under
/// a follower pressure anchored on the bottom and top walls (the membrane),
/// the top wall shearing and compressing at a fixed velocity.
fn membrane_box(threads: usize) -> Simulation {
    let n_side = 60;
    let mut sim = boxed_packing(n_side, 0.5, 11, threads);
    sim.set_wall_velocity(2, [0.02, -0.002]).unwrap();
    sim.set_wall_active(3, false).unwrap();
    let chain: Vec<usize> = (0..n_side).collect();
    sim.add_pressure_chain(&chain, 2.0e5, Some(0), Some(2))
        .unwrap();
    sim
}

/// The common 4,000-disk periodic packing under pure shear of its cell, with
/// local damping.
fn sheared_packing(threads: usize) -> Simulation {
    let mut sim = bench_packing(0.9, 0.2, threads);
    let mut cell = sim.cell().cloned().unwrap();
    cell.velocity_gradient = [[-0.05, 0.0], [0.0, 0.05]];
    sim.set_cell(Some(cell)).unwrap();
    let mut p = sim.params();
    p.local_damping = 0.1;
    sim.set_params(p).unwrap();
    sim
}

/// Every touching pair of `sim` (not bonded already) cemented by a parallel
/// bond of strengths drawn by a seeded generator between `low` and 8 `low`
/// (Pa), so that some break under the loading and most hold.
fn cement_contacts(sim: &mut Simulation, low: f64, seed: u64) {
    let contacts = sim.contacts().unwrap();
    let pairs: Vec<(usize, usize)> = (0..contacts.i.len())
        .filter(|&k| !contacts.bonded[k])
        .map(|k| (contacts.i[k] as usize, contacts.j[k] as usize))
        .collect();
    let mut rng = Rng::new(seed);
    let kn_bar = KN / (2.0e-3);
    let specs: Vec<CementSpec> = pairs
        .iter()
        .map(|_| CementSpec {
            kind: CementKind::Parallel,
            radius_multiplier: rng.uniform(0.5, 1.0),
            normal_stiffness: kn_bar,
            shear_stiffness: 0.5 * kn_bar,
            tensile_strength: rng.uniform(low, 8.0 * low),
            cohesion: rng.uniform(low, 8.0 * low),
            friction_angle: 20.0,
        })
        .collect();
    sim.add_cement_bonds(&pairs, &specs).unwrap();
}

/// The sheared periodic packing with every contact cemented: the bonds'
/// nearest image in a deforming cell, their breaks in tension and shear.
fn cemented_sheared_packing(threads: usize) -> Simulation {
    let mut sim = sheared_packing(threads);
    cement_contacts(&mut sim, 1.0e6, 5);
    sim
}

/// The servo box with every contact cemented and the top wall squeezing and
/// shearing the sample: walls, the membrane's permanent bonds beside cement.
fn cemented_box(threads: usize) -> Simulation {
    let mut sim = membrane_box(threads);
    cement_contacts(&mut sim, 2.0e6, 9);
    sim
}

/// A small frictionless-to-frictional periodic packing in simple shear (a
/// velocity gradient with an off-diagonal term), the serial path.
fn simple_shear(threads: usize) -> Simulation {
    let mut sim = dense_periodic(18, 1.0e-3, 0.3, 21, threads);
    let mut cell = sim.cell().cloned().unwrap();
    cell.velocity_gradient = [[0.0, 0.4], [0.0, 0.0]];
    sim.set_cell(Some(cell)).unwrap();
    sim
}

/// Two layers of disks on a floor under gravity, thrown sideways with spins:
/// they slide on the floor and on each other (friction 0.3), until rolling.
fn sliding_layers(threads: usize) -> Simulation {
    let mut rng = Rng::new(7);
    let (mut pos, mut rad) = (Vec::new(), Vec::new());
    for layer in 0..2 {
        for k in 0..40 {
            let r = rng.uniform(0.9e-3, 1.1e-3);
            let x = 2.3e-3 * k as f64 + if layer == 1 { 1.15e-3 } else { 0.0 };
            let y = 1.0e-3 + 1.9e-3 * layer as f64 - 0.02e-3;
            pos.push([x, y]);
            rad.push(r);
        }
    }
    let particles = Particles::new(pos, rad, vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(
        particles,
        ContactModel::linear(KN, 0.5 * KN, 0.3),
        1.0e-4,
        threads,
    )
    .unwrap();
    sim.set_params(StepParameters {
        time_step: 1.0e-4,
        local_damping: 0.0,
        gravity: [0.0, -9.81],
        max_overlap_ratio: 0.5,
    })
    .unwrap();
    let floor = Wall::new(
        WallShape::Line {
            point: [0.0, 0.0],
            normal: [0.0, 1.0],
        },
        0,
    )
    .unwrap();
    sim.add_wall(floor);
    set_random_motion(
        &mut sim,
        &mut rng,
        (-0.01, 0.04),
        (-0.005, 0.005),
        (-40.0, 40.0),
    );
    sim
}

#[test]
fn a_servo_walled_box_follows_its_recorded_trajectory() {
    let sim = check("servo box", servo_box, 3000, 1000, 0xbd85_c2ed_09bd_4e08);
    // the servo walls moved, and the stress on them is near its target
    for id in [1, 2] {
        let w = &sim.walls()[id];
        assert!(w.displacement != [0.0, 0.0]);
        assert!(w.contact_count > 30);
    }
}

#[test]
fn a_membrane_box_follows_its_recorded_trajectory() {
    let sim = check(
        "membrane box",
        membrane_box,
        3000,
        750,
        0x8adc_d926_a98f_cbc0,
    );
    assert!(sim.walls()[2].displacement[0] > 0.0 && sim.energy().boundary_work != 0.0);
}

#[test]
fn a_sheared_periodic_packing_follows_its_recorded_trajectory() {
    check(
        "sheared packing",
        sheared_packing,
        2500,
        500,
        0xda32_f041_0c5f_3d29,
    );
}

#[test]
fn a_small_simple_shear_follows_its_recorded_trajectory() {
    check(
        "simple shear",
        simple_shear,
        5000,
        5000,
        0xffd5_e34a_acbb_1ba2,
    );
}

#[test]
fn sliding_layers_follow_their_recorded_trajectory() {
    let sim = check(
        "sliding layers",
        sliding_layers,
        5000,
        1000,
        0x50c6_bb99_f467_3f76,
    );
    // the disks slid (friction dissipated energy) and rest on the floor
    assert!(sim.energy().friction_dissipated > 0.0);
    assert!(sim.measurements().wall_contact_count > 20);
}

/// The common packing sheared in two groups of disks with three different
/// undamped models (grain-grain, grain-other, other-other), so that every pair
/// reads its own model: the four-pair loop and the one-pair loop must end in
/// the same bits, on 1 and 2 threads.
#[test]
fn two_groups_with_their_own_models_give_the_same_bits_with_the_vector_kernels() {
    let build = |threads: usize| {
        let mut sim = bench_packing(0.5, 0.2, threads);
        let n = sim.particles().len();
        let groups: Vec<u8> = (0..n).map(|k| (k % 3 == 0) as u8).collect();
        sim.set_groups(&groups).unwrap();
        sim.set_contact_model(0, 1, ContactModel::linear(0.7 * KN, 0.4 * KN, 0.2))
            .unwrap();
        sim.set_contact_model(1, 1, ContactModel::linear(1.3 * KN, 0.9 * KN, 0.05))
            .unwrap();
        let mut cell = sim.cell().cloned().unwrap();
        cell.velocity_gradient = [[-0.2, 0.05], [0.0, 0.2]];
        sim.set_cell(Some(cell)).unwrap();
        sim
    };
    for threads in [1, 2] {
        let mut runs = Vec::new();
        for vector in [true, false] {
            let mut sim = build(threads);
            sim.set_simd(vector);
            for _ in 0..3 {
                sim.run(500).unwrap();
            }
            assert!(sim.neighbors().build_count > 1, "no rebuild");
            assert!(sim.energy().friction_dissipated > 0.0, "no contact slid");
            runs.push((trajectory_hash(&sim), contact_list_bits(&mut sim)));
        }
        assert_eq!(
            runs[0].0, runs[1].0,
            "{threads} thread(s): trajectories differ"
        );
        assert!(
            runs[0].1 == runs[1].1,
            "{threads} thread(s): contact lists differ"
        );
    }
}

#[test]
fn a_cemented_sheared_packing_follows_its_recorded_trajectory() {
    let sim = check(
        "cemented sheared packing",
        cemented_sheared_packing,
        2500,
        500,
        0xcd3f_b3a4_b6cf_69a5,
    );
    let (intact, broken) = (sim.cement().bonds.len(), sim.cement().breaks.len());
    assert!(
        broken > 20 && intact > 10 * broken,
        "{broken} broke, {intact} hold"
    );
}

#[test]
fn a_cemented_membrane_box_follows_its_recorded_trajectory() {
    let sim = check(
        "cemented membrane box",
        cemented_box,
        3000,
        750,
        0x0797_76e0_4b43_c604,
    );
    let (intact, broken) = (sim.cement().bonds.len(), sim.cement().breaks.len());
    assert!(
        broken > 20 && intact > 5 * broken,
        "{broken} broke, {intact} hold"
    );
}
