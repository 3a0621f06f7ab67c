//! Rigid clumps of pebbles: conservation, friction on an incline, no contact
//! inside a body, the same bits on 1-4 threads and after a resume, the time
//! step, the periodic cell, and the refusals of bad bodies.
mod common;
use common::*;
use grainlab_core::body::GivenMass;
use grainlab_core::{
    BodySpec, ContactModel, EngineError, Particles, PeriodicCell, Simulation, StepParameters, Wall,
    WallShape,
};

/// The pebble centres of an equilateral trimer of pebbles of radius `r`
/// whose centres are `1.2 r` apart, centred on `c`, turned by `angle`.
fn trimer(c: [f64; 2], r: f64, angle: f64) -> Vec<[f64; 2]> {
    let arm = 1.2 * r / 3f64.sqrt();
    (0..3)
        .map(|k| {
            let a =
                angle + std::f64::consts::FRAC_PI_2 + k as f64 * 2.0 * std::f64::consts::PI / 3.0;
            [c[0] + arm * a.cos(), c[1] + arm * a.sin()]
        })
        .collect()
}

/// Bodies of consecutive triples of particles `0..3 n`.
fn triples(n: usize) -> Vec<BodySpec> {
    (0..n)
        .map(|b| BodySpec {
            pebbles: vec![3 * b, 3 * b + 1, 3 * b + 2],
            angle: 0.0,
            given: None,
        })
        .collect()
}

fn params(dt: f64, alpha: f64, gravity: [f64; 2]) -> StepParameters {
    StepParameters {
        time_step: dt,
        local_damping: alpha,
        gravity,
        max_overlap_ratio: 0.5,
    }
}

/// Total momentum and angular momentum about the origin of the clumps, and
/// their kinetic energy (half-step velocities, `M X x V + I w`).
fn momenta(sim: &Simulation) -> ([f64; 2], f64, f64) {
    let c = sim.clumps();
    let (mut p, mut l, mut k) = ([0.0; 2], 0.0, 0.0);
    for b in 0..c.len() {
        let (m, v, x, w) = (
            c.mass[b],
            c.velocity[b],
            c.centroid[b],
            c.angular_velocity[b],
        );
        p[0] += m * v[0];
        p[1] += m * v[1];
        l += m * (x[0] * v[1] - x[1] * v[0]) + c.inertia[b] * w;
        k += 0.5 * m * (v[0] * v[0] + v[1] * v[1]) + 0.5 * c.inertia[b] * w * w;
    }
    (p, l, k)
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

#[test]
fn a_free_clump_keeps_its_momenta_energy_and_shape_over_1e5_steps() {
    let r = 1.0e-3;
    let particles = Particles::new(trimer([0.0, 0.0], r, 0.3), vec![r; 3], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), 1e-6, 1).unwrap();
    sim.add_bodies(&triples(1)).unwrap();
    sim.set_clump_velocities(&[[0.3, -0.2]], &[250.0]).unwrap();
    let (p0, l0, k0) = momenta(&sim);
    let (x0, theta0) = (sim.clumps().centroid[0], sim.clumps().angle[0]);
    let gap = |sim: &Simulation| {
        let x = sim.particles().position.clone();
        [
            distance(x[0], x[1]),
            distance(x[1], x[2]),
            distance(x[2], x[0]),
        ]
    };
    let shape = gap(&sim);
    sim.run(100_000).unwrap();
    let (p, l, k) = momenta(&sim);
    // no force: the momentum and the kinetic energy do not change by one bit;
    // the angular momentum about the origin only by the drift's round-off,
    // at most about an ulp of the centroid per step (M |V| n eps |X|)
    assert_eq!((p, k), (p0, k0));
    let c = sim.clumps();
    let drift_round_off = c.mass[0]
        * distance(c.velocity[0], [0.0; 2])
        * 1e5
        * f64::EPSILON
        * distance(c.centroid[0], [0.0; 2]);
    assert!(
        (l - l0).abs() < drift_round_off,
        "angular momentum {l0} -> {l}"
    );
    assert_eq!(sim.energy().kinetic.to_bits(), k0.to_bits());
    let t = sim.time();
    let c = sim.clumps();
    let x = c.centroid[0];
    assert!(
        distance(x, [x0[0] + 0.3 * t, x0[1] - 0.2 * t]) < 1e-12,
        "{x:?}"
    );
    assert!((c.angle[0] - (theta0 + 250.0 * t)).abs() < 1e-10);
    for (a, b) in gap(&sim).iter().zip(&shape) {
        assert!(
            (a / b - 1.0).abs() < 1e-13,
            "the clump changed shape: {a} vs {b}"
        );
    }
    // every pebble moves with the body's rigid velocity
    let q = sim.internal_index(0);
    let (xq, vq) = (sim.particles().position[q], sim.particles().velocity[q]);
    let arm = [xq[0] - x[0], xq[1] - x[1]];
    let rigid = [0.3 - 250.0 * arm[1], -0.2 + 250.0 * arm[0]];
    assert!(distance(vq, rigid) < 1e-12, "{vq:?} vs {rigid:?}");
    assert_eq!(sim.particles().angular_velocity[q], 250.0);
}

#[test]
fn colliding_frictionless_clumps_keep_momentum_and_angular_momentum() {
    // two trimers hit off-centre and spin away: the contact forces pass through
    // the pebbles' centres, so momentum and angular momentum (leapfrog's
    // staggered sums) hold to round-off; without damping the energy comes back
    let r = 1.0e-3;
    let mut centres = trimer([0.0, 0.0], r, 0.0);
    centres.extend(trimer([4.0 * r, 0.9 * r], r, 0.7));
    let particles = Particles::new(centres, vec![r; 6], vec![DENSITY]).unwrap();
    let m = DENSITY * std::f64::consts::PI * r * r;
    let dt = 0.02 * (m / KN).sqrt();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.0), dt, 1).unwrap();
    sim.add_bodies(&triples(2)).unwrap();
    sim.set_clump_velocities(&[[0.01, 0.0], [-0.01, 0.002]], &[0.0, 5.0])
        .unwrap();
    sim.run(1).unwrap();
    let (p0, l0, k0) = momenta(&sim);
    let c = sim.clumps();
    let scale: f64 = (0..2)
        .map(|b| c.mass[b] * distance(c.velocity[b], [0.0; 2]))
        .sum();
    let mut touched = false;
    for _ in 0..400 {
        sim.run(50).unwrap();
        touched |= sim.measurements().contact_count > 0;
        let (p, l, _) = momenta(&sim);
        assert!((p[0] - p0[0]).abs() < 1e-14 * scale && (p[1] - p0[1]).abs() < 1e-14 * scale);
        assert!(
            ((l - l0) / l0).abs() < 1e-11,
            "angular momentum {l0} -> {l}"
        );
    }
    assert!(touched, "the clumps never met");
    assert_eq!(sim.measurements().contact_count, 0, "still in contact");
    let (_, _, k) = momenta(&sim);
    assert!((k / k0 - 1.0).abs() < 2e-3, "kinetic energy {k0} -> {k}");
    let w = &sim.clumps().angular_velocity;
    assert!(
        w[0].abs() > 1.0,
        "the off-centre hit did not spin the first clump: {w:?}"
    );
}

/// A dimer of two pebbles of radius 1 mm, 1.5 mm apart, their centres at
/// height `y` over a floor (a line wall at y = 0).
fn dimer_on_floor(y: f64, model: ContactModel, dt: f64) -> Simulation {
    let r = 1.0e-3;
    let particles =
        Particles::new(vec![[0.0, y], [1.5 * r, y]], vec![r; 2], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, model, dt, 1).unwrap();
    let floor = WallShape::Line {
        point: [0.0, 0.0],
        normal: [0.0, 1.0],
    };
    sim.add_wall(Wall::new(floor, 0).unwrap());
    sim.add_bodies(&[BodySpec {
        pebbles: vec![0, 1],
        angle: 0.0,
        given: None,
    }])
    .unwrap();
    sim
}

/// A dimer lying on a horizontal wall, gravity `g` tilted by `theta` from
/// the wall's normal, Coulomb friction `mu`: the clump's centroid's x
/// displacement and x velocity after `steps` steps and after twice as many.
fn dimer_on_incline(theta: f64, mu: f64, steps: u64) -> [[f64; 2]; 2] {
    let (r, g) = (1.0e-3, 9.81);
    let m = DENSITY * std::f64::consts::PI * r * r;
    // at about the resting overlap: two disks' weight on two contacts (the
    // dimer's union weighs a little less)
    let y = r - m * g * theta.cos() / KN;
    let dt = 0.05 * (m / KN).sqrt();
    let model = ContactModel {
        normal_damping_ratio: 0.3,
        shear_damping_ratio: 0.3,
        ..ContactModel::linear(KN, KN, mu)
    };
    let mut sim = dimer_on_floor(y, model, dt);
    sim.set_params(params(dt, 0.0, [g * theta.sin(), -g * theta.cos()]))
        .unwrap();
    let x0 = sim.clumps().centroid[0][0];
    let mut out = [[0.0; 2]; 2];
    for reading in out.iter_mut() {
        sim.run(steps).unwrap();
        let c = sim.clumps();
        *reading = [c.centroid[0][0] - x0, c.velocity[0][0]];
    }
    out
}

#[test]
fn a_clump_on_an_incline_sticks_below_the_friction_angle_and_slides_above() {
    let (mu, r, g) = (0.5f64, 1.0e-3, 9.81);
    let m = DENSITY * std::f64::consts::PI * r * r;
    let dt = 0.05 * (m / KN).sqrt();
    let steps = 40_000;
    // below: tan(theta) = mu / 2 (the springs' overshoot as the load comes on
    // at once stays below the cap); it settles on its shear springs (about
    // 0.01 r, and rocks on them by a few hundredths of a radian) and stays there
    let below = dimer_on_incline((0.5 * mu).atan(), mu, steps);
    assert!(below[1][0].abs() < 0.1 * r, "it slid: x {:?}", below);
    assert!(
        (below[1][0] - below[0][0]).abs() < 1e-6 * r,
        "it moved on: {below:?}"
    );
    // above: tan(theta) = 1.25 mu; it slides at g (sin(theta) - mu cos(theta))
    let theta = (1.25 * mu).atan();
    let above = dimer_on_incline(theta, mu, steps);
    let expected = g * (theta.sin() - mu * theta.cos());
    let t = steps as f64 * dt;
    let a = (above[1][1] - above[0][1]) / t;
    assert!(
        (a / expected - 1.0).abs() < 1e-3,
        "a = {a}, Coulomb gives {expected}"
    );
}

/// Trimers of pebbles of radius `r` on a jittered grid in a periodic cell,
/// random angles and velocities: at least `n_side^2` clumps.
fn trimer_gas(n_side: usize, model: ContactModel, threads: usize) -> Simulation {
    let r = 1.0e-3;
    let s = 3.2 * r;
    let mut rng = Rng::new(11);
    let mut centres = Vec::new();
    for a in 0..n_side {
        for b in 0..n_side {
            let c = [(a as f64 + 0.5) * s, (b as f64 + 0.5) * s];
            centres.extend(trimer(c, r * rng.uniform(0.9, 1.1), rng.uniform(0.0, 6.3)));
        }
    }
    let n = centres.len();
    let particles = Particles::new(centres, vec![r; n], vec![DENSITY]).unwrap();
    let m = DENSITY * std::f64::consts::PI * r * r;
    let dt = 0.05 * (m / KN).sqrt();
    let mut sim = Simulation::new(particles, model, dt, threads).unwrap();
    let l = n_side as f64 * s;
    sim.set_cell(Some(
        PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap(),
    ))
    .unwrap();
    sim.set_params(params(dt, 0.1, [0.0; 2])).unwrap();
    sim.add_bodies(&triples(n / 3)).unwrap();
    let v: Vec<[f64; 2]> = (0..n / 3)
        .map(|_| [rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05)])
        .collect();
    let w: Vec<f64> = (0..n / 3).map(|_| rng.uniform(-20.0, 20.0)).collect();
    sim.set_clump_velocities(&v, &w).unwrap();
    sim
}

/// Every bit of the pebbles' and the clumps' state.
fn state_bits(sim: &Simulation) -> Vec<u64> {
    let p = sim.particles();
    let c = sim.clumps();
    let mut bits = Vec::new();
    for e in 0..p.len() {
        let q = sim.internal_index(e);
        bits.extend(
            p.position[q]
                .iter()
                .chain(&p.velocity[q])
                .map(|x| x.to_bits()),
        );
        bits.push(p.angular_velocity[q].to_bits());
    }
    for b in 0..c.len() {
        bits.extend(
            c.centroid[b]
                .iter()
                .chain(&c.velocity[b])
                .map(|x| x.to_bits()),
        );
        bits.extend([c.angle[b].to_bits(), c.angular_velocity[b].to_bits()]);
    }
    bits
}

#[test]
fn no_contact_between_pebbles_of_one_clump_is_ever_listed() {
    let mut sim = trimer_gas(8, ContactModel::linear(KN, KN, 0.5), 1);
    let body = sim.body_of_particles();
    let mut seen = 0;
    for _ in 0..20 {
        sim.run(100).unwrap();
        let c = sim.contacts().unwrap();
        seen += c.i.len();
        for (&i, &j) in c.i.iter().zip(&c.j) {
            assert_ne!(
                body[i as usize], body[j as usize],
                "pebbles {i} and {j} of one body touch"
            );
        }
    }
    assert!(seen > 100, "too few contacts to tell: {seen}");
}

#[test]
fn clumps_give_the_same_bits_on_one_to_four_threads_and_after_a_resume() {
    for model in [
        ContactModel::linear(KN, KN, 0.5),
        ContactModel::hertz_mindlin(7.0e10, 0.25, 0.5, 0.5),
    ] {
        // 1,200 trimers: 3,600 pebbles, enough for the team to run
        let run = |threads: usize| {
            let mut sim = trimer_gas(20, model, threads);
            sim.run(300).unwrap();
            let contacts = sim.measurements().contact_count;
            assert!(contacts > 150, "{contacts} contacts");
            state_bits(&sim)
        };
        let one = run(1);
        for threads in 2..=4 {
            assert!(
                run(threads) == one,
                "{threads} threads differ ({:?})",
                model.law
            );
        }
        let mut sim = trimer_gas(20, model, 2);
        sim.run(150).unwrap();
        let saved = sim.to_bytes().unwrap();
        sim.run(150).unwrap();
        let mut resumed = Simulation::from_bytes(&saved).unwrap();
        resumed.run(150).unwrap();
        assert!(
            state_bits(&resumed) == state_bits(&sim),
            "the resume differs"
        );
        assert!(state_bits(&sim) == one);
    }
}

#[test]
fn a_clump_in_a_shearing_cell_follows_the_flow_rigidly_across_the_boundary() {
    // a trimer straddling the cell's corner, at rest relative to the flow:
    // its centroid moves with the imposed shear, its shape never changes
    let r = 1.0e-3;
    let l = 10.0 * r;
    let centres = trimer([0.1 * r, 0.2 * r], r, 0.4);
    let particles = Particles::new(centres, vec![r; 3], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), 1e-6, 1).unwrap();
    sim.set_cell(Some(
        PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap(),
    ))
    .unwrap();
    sim.add_bodies(&triples(1)).unwrap();
    let x0 = sim.clumps().centroid[0];
    let rate = 50.0;
    sim.set_velocity_gradient([[0.0, rate], [0.0, 0.0]])
        .unwrap();
    sim.run(20_000).unwrap();
    let t = sim.time();
    let c = sim.clumps();
    let cell = sim.cell().unwrap();
    let expected = [x0[0] + rate * t * x0[1], x0[1]];
    let off = [
        c.centroid[0][0] - expected[0],
        c.centroid[0][1] - expected[1],
    ];
    let off = grainlab_core::cell::minimum_image(Some(cell), off);
    assert!(
        distance(off, [0.0; 2]) < 1e-12,
        "{:?} vs {expected:?}",
        c.centroid[0]
    );
    assert_eq!(c.angular_velocity[0], 0.0);
    let x = &sim.particles().position;
    let gap = |a: [f64; 2], b: [f64; 2]| {
        let d = grainlab_core::cell::minimum_image(Some(cell), [b[0] - a[0], b[1] - a[1]]);
        (d[0] * d[0] + d[1] * d[1]).sqrt()
    };
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        assert!(
            (gap(x[i], x[j]) / (1.2 * r) - 1.0).abs() < 1e-12,
            "{}",
            gap(x[i], x[j])
        );
    }
    assert!(
        sim.neighbors().build_count > 1,
        "no rebuild wrapped the pebbles"
    );
}

#[test]
fn a_clumps_critical_time_step_is_its_own_mass_over_its_contacts() {
    // a dimer pressed on a wall by both pebbles: sqrt(M / 2 kn) and
    // sqrt(I / sum(kn |r|^2 + ks (|r| + R)^2)) over its two contacts
    let r = 1.0e-3;
    let mut sim = dimer_on_floor(0.9 * r, ContactModel::linear(KN, 0.5 * KN, 0.5), 1e-7);
    let c = sim.clumps();
    let (m, i) = (c.mass[0], c.inertia[0]);
    let arm = 0.75 * r;
    let rotation = 2.0 * (KN * arm * arm + 0.5 * KN * (arm + r).powi(2));
    let expected = (m / (2.0 * KN)).sqrt().min((i / rotation).sqrt());
    let dt = sim.critical_time_step(1.0).unwrap();
    assert!((dt / expected - 1.0).abs() < 1e-14, "{dt} vs {expected}");
}

fn refusal(result: grainlab_core::Result<()>) -> (String, String) {
    match result {
        Err(EngineError::InvalidInput { field, message }) => (field, message),
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn bad_bodies_are_refused_before_any_change() {
    let r = 1.0e-3;
    let mut centres = trimer([0.0, 0.0], r, 0.0);
    centres.extend(trimer([5.0 * r, 0.0], r, 0.0));
    let particles = Particles::new(centres, vec![r; 6], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), 1e-7, 1).unwrap();
    let body = |pebbles: Vec<usize>| BodySpec {
        pebbles,
        angle: 0.0,
        given: None,
    };
    let (field, message) = refusal(sim.add_bodies(&[body(vec![0, 1, 2]), body(vec![2, 3])]));
    assert_eq!(field, "bodies[1]");
    assert!(
        message.contains("particle 2 is also a pebble of body 0"),
        "{message}"
    );
    let (field, message) = refusal(sim.add_bodies(&[body(vec![0, 1]), body(vec![])]));
    assert_eq!(field, "bodies[1]");
    assert!(message.contains("at least one pebble"));
    let (field, _) = refusal(sim.add_bodies(&[body(vec![0, 9])]));
    assert_eq!(field, "bodies[0].pebbles");
    let zero_mass = BodySpec {
        given: Some(GivenMass {
            mass: 0.0,
            moment_of_inertia: 1.0,
            centroid: [0.0, 0.0],
        }),
        ..body(vec![0, 1, 2])
    };
    assert_eq!(refusal(sim.add_bodies(&[zero_mass])).0, "bodies[0].mass");
    let mut densities = vec![DENSITY; 6];
    densities[4] = 2.0 * DENSITY;
    sim.set_densities(&densities).unwrap();
    let (field, message) = refusal(sim.add_bodies(&[body(vec![3, 4, 5])]));
    assert_eq!(field, "bodies[0]");
    assert!(message.contains("different densities"), "{message}");
    sim.set_densities(&[DENSITY; 6]).unwrap();
    sim.set_fixity(&[1, 0, 0, 0, 0, 0]).unwrap();
    assert!(refusal(sim.add_bodies(&[body(vec![0, 1, 2])]))
        .1
        .contains("different fixity"));
    sim.set_fixity(&[0; 6]).unwrap();
    sim.add_bond(0, 1, KN, KN, None).unwrap();
    assert!(refusal(sim.add_bodies(&[body(vec![0, 1, 2])]))
        .1
        .contains("bonded"));
    // nothing was made of all that
    assert!(sim.clumps().is_empty());
    assert_eq!(sim.body_of_particles(), vec![0, 1, 2, 3, 4, 5]);
    // a clump, then what may not be done to its pebbles
    sim.add_bodies(&[body(vec![3, 4]), body(vec![5])]).unwrap();
    assert_eq!(sim.body_of_particles(), vec![1, 2, 3, 0, 0, 4]);
    assert!(refusal(sim.add_bodies(&[body(vec![4, 5])]))
        .1
        .contains("already a pebble"));
    assert!(refusal(sim.add_bond(3, 4, KN, KN, None))
        .1
        .contains("one clump"));
    let mut x = sim.to_external(&sim.particles().position);
    let mut radii = vec![r; 6];
    radii[3] = 2.0 * r;
    assert_eq!(refusal(sim.set_radii(&radii)).0, "radii[3]");
    assert!(refusal(sim.set_fixity(&[0, 0, 0, 1, 0, 0]))
        .1
        .contains("fixed as one"));
    // the same positions, or a moved plain disk, are fine
    x[0][1] += r;
    sim.set_positions(&x).unwrap();
    sim.set_fixity(&[0, 0, 0, 7, 7, 0]).unwrap();
    assert_eq!(sim.clumps().fixity[0], 7);
    assert!(matches!(
        sim.add_pressure_chain(&[5, 3], 1.0, None, None),
        Err(EngineError::InvalidInput { .. })
    ));
}

#[test]
fn a_fixed_clump_stays_put_and_bodies_of_one_disk_change_nothing() {
    let r = 1.0e-3;
    let run = |bodies: bool| {
        let mut sim = dense_periodic(12, 2.0 * r, 0.5, 3, 1);
        if bodies {
            let singles: Vec<BodySpec> = (0..144)
                .map(|k| BodySpec {
                    pebbles: vec![k],
                    angle: 0.0,
                    given: None,
                })
                .collect();
            sim.add_bodies(&singles).unwrap();
            assert!(sim.clumps().is_empty());
        }
        sim.run(500).unwrap();
        state_bits(&sim)
    };
    assert!(run(true) == run(false));
    // a clump fixed in x, y and rotation among moving disks does not move
    let mut sim = dense_periodic(12, 2.0 * r, 0.5, 3, 1);
    let mut fixity = vec![0u8; 144];
    fixity[0] = 7;
    fixity[1] = 7;
    sim.set_fixity(&fixity).unwrap();
    sim.add_bodies(&[BodySpec {
        pebbles: vec![0, 1],
        angle: 0.0,
        given: None,
    }])
    .unwrap();
    let before = (sim.clumps().centroid[0], sim.clumps().angle[0]);
    sim.run(100).unwrap();
    assert!(sim.measurements().contact_count > 100);
    assert_eq!((sim.clumps().centroid[0], sim.clumps().angle[0]), before);
    assert!(
        sim.clumps().force[0] != [0.0, 0.0],
        "no force reached the fixed clump"
    );
}

#[test]
fn the_energy_ledger_balances_with_clumps_friction_damping_and_gravity() {
    // kinetic (each clump's once) + elastic + friction + local damping - the
    // work of gravity stays constant while 1,200 trimers collide and fall
    // through the periodic cell, to 2e-3 of the energy that changed form (the
    // disks' own test allows 2e-3 of the total; local damping's work is booked
    // at the mean of the half-step velocities, an estimate of first order in dt)
    let mut sim = trimer_gas(20, ContactModel::linear(KN, KN, 0.5), 1);
    let mut params = sim.params();
    params.gravity = [0.0, -9.81];
    sim.set_params(params).unwrap();
    sim.run(1).unwrap();
    let b0 = sim.energy().balance();
    sim.run(3000).unwrap();
    let e = sim.energy();
    assert!(
        e.friction_dissipated > 0.1 * b0 && e.damping_dissipated > 0.1 * b0,
        "{e:?}"
    );
    let turnover = e.friction_dissipated + e.damping_dissipated + e.external_work;
    let drift = (e.balance() - b0) / turnover;
    assert!(drift.abs() < 2e-3, "balance drift {drift} of {turnover} J");
}

#[test]
fn a_scaled_clump_is_the_similar_clump_of_the_same_density() {
    use grainlab_core::body::ClumpTemplate;
    let r = 1.0e-3;
    let mut centres = trimer([0.0, 0.0], r, 0.2);
    centres.extend(trimer([6.0 * r, 0.0], r, 1.1));
    let particles = Particles::new(centres, vec![r; 6], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), 1e-7, 1).unwrap();
    sim.add_bodies(&triples(2)).unwrap();
    let before = sim.to_external(&sim.particles().position);
    let centroids = sim.clumps().centroid.clone();
    let factors = [1.5, 0.8];
    sim.scale_clumps(&factors).unwrap();
    let x = sim.to_external(&sim.particles().position);
    let radii = sim.to_external(&sim.particles().radius);
    for b in 0..2 {
        let (f, c) = (factors[b], centroids[b]);
        let pebbles = &x[3 * b..3 * b + 3];
        for (p, q) in pebbles.iter().zip(&before[3 * b..3 * b + 3]) {
            let expected = [c[0] + f * (q[0] - c[0]), c[1] + f * (q[1] - c[1])];
            assert!(distance(*p, expected) < 1e-15, "{p:?} vs {expected:?}");
        }
        assert_eq!(radii[3 * b], f * r);
        let (similar, at) =
            ClumpTemplate::from_pebbles(pebbles, &radii[3 * b..3 * b + 3], DENSITY).unwrap();
        let clumps = sim.clumps();
        assert!((clumps.mass[b] / similar.mass() - 1.0).abs() < 1e-13);
        assert!((clumps.inertia[b] / similar.moment_of_inertia() - 1.0).abs() < 1e-13);
        assert!(distance(clumps.centroid[b], at.centroid) < 1e-15);
    }
    for bad in [[0.0, 1.0], [1.0, f64::NAN], [-1.0, 1.0]] {
        assert!(matches!(
            sim.scale_clumps(&bad),
            Err(EngineError::InvalidInput { .. })
        ));
    }
    assert_eq!(refusal(sim.scale_clumps(&[1.0])).0, "factors");
}

#[test]
fn setting_a_clumps_pebbles_moves_the_clump_rigidly() {
    // positions: a clump moved and turned as a whole is placed there exactly;
    // velocities: zeros stop it, a rigid field gives back its motion
    let r = 1.0e-3;
    let centres = trimer([0.0, 0.0], r, 0.0);
    let particles = Particles::new(centres, vec![r; 3], vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), 1e-7, 1).unwrap();
    sim.add_bodies(&triples(1)).unwrap();
    let (c0, a0) = (sim.clumps().centroid[0], sim.clumps().angle[0]);
    let (turn, shift) = (0.4f64, [2.0e-3, -1.0e-3]);
    let (s, c) = turn.sin_cos();
    let moved: Vec<[f64; 2]> = sim
        .to_external(&sim.particles().position)
        .iter()
        .map(|p| {
            let d = [p[0] - c0[0], p[1] - c0[1]];
            [
                c0[0] + shift[0] + c * d[0] - s * d[1],
                c0[1] + shift[1] + s * d[0] + c * d[1],
            ]
        })
        .collect();
    sim.set_positions(&moved).unwrap();
    let clumps = sim.clumps();
    assert!(distance(clumps.centroid[0], [c0[0] + shift[0], c0[1] + shift[1]]) < 1e-15);
    assert!((clumps.angle[0] - (a0 + turn)).abs() < 1e-14);
    for (p, q) in sim
        .to_external(&sim.particles().position)
        .iter()
        .zip(&moved)
    {
        assert!(distance(*p, *q) < 1e-15);
    }
    sim.set_clump_velocities(&[[0.2, -0.1]], &[40.0]).unwrap();
    let rigid = sim.to_external(&sim.particles().velocity);
    sim.set_velocities(&[[0.0; 2]; 3]).unwrap();
    assert_eq!(
        (sim.clumps().velocity[0], sim.clumps().angular_velocity[0]),
        ([0.0, 0.0], 0.0)
    );
    sim.set_velocities(&rigid).unwrap();
    let clumps = sim.clumps();
    assert!(distance(clumps.velocity[0], [0.2, -0.1]) < 1e-15);
    assert!((clumps.angular_velocity[0] - 40.0).abs() < 1e-12);
    sim.set_angular_velocities(&[1.0, 2.0, 6.0]).unwrap();
    assert_eq!(sim.clumps().angular_velocity[0], 3.0);
    assert!(sim.particles().angular_velocity.iter().all(|&w| w == 3.0));
}
