//! Rolling resistance (the elastic-plastic rolling spring, `law/rolling.rs`)
//! against closed-form results: a disk rolling to a stop on a floor, a disk
//! held on an incline up to `tan(theta) = mu_r` and rolling above it, the
//! elastic rolling oscillation; and its bits on 1 and 2 threads.
mod common;
use common::*;
use grainlab_core::{ContactModel, Particles, Simulation, StepParameters, Wall, WallShape};

const R: f64 = 1.0e-3;
const G: f64 = 9.81;

fn mass() -> f64 {
    DENSITY * std::f64::consts::PI * R * R
}

/// `I = m r^2 / 2`, the disk's moment of inertia.
fn inertia() -> f64 {
    0.5 * mass() * R * R
}

/// Table 1's stiffness, sliding friction `mu`, rolling friction `mu_r` (its
/// stiffness from the rule), normal and shear dashpots at 0.3 so that the
/// disk's bounce on the floor dies out.
fn model(mu: f64, mu_r: f64) -> ContactModel {
    let mut m = ContactModel::linear(KN, KN, mu);
    m.rolling_friction = mu_r;
    m.normal_damping_ratio = 0.3;
    m.shear_damping_ratio = 0.3;
    m
}

/// The rolling stiffness rule against a wall, `2.25 kn mu_r^2 R^2`.
fn rule_stiffness(mu_r: f64) -> f64 {
    2.25 * KN * mu_r * mu_r * R * R
}

/// A disk resting on the floor `y = 0` (at its equilibrium overlap under
/// `gravity`, the floor's normal `+y`), time step
/// `t_c / 50`.
fn disk_on_floor(model: ContactModel, gravity: [f64; 2]) -> Simulation {
    let t_c = std::f64::consts::PI * (mass() / KN).sqrt();
    let dt = t_c / 50.0;
    let overlap = -mass() * gravity[1] / KN;
    let mut sim = disks(vec![[0.0, R - overlap]], vec![R], model, dt);
    sim.set_params(StepParameters {
        time_step: dt,
        local_damping: 0.0,
        gravity,
        max_overlap_ratio: 0.9,
    })
    .unwrap();
    let floor = Wall::new(
        WallShape::Line {
            point: [0.0, 0.0],
            normal: [0.0, 1.0],
        },
        1,
    )
    .unwrap();
    sim.add_wall(floor);
    sim.set_contact_model(0, 1, model).unwrap();
    sim
}

/// A disk rolling on a flat floor with the rolling moment at its cap
/// `mu_r r N`, `N = m g`, and friction keeping it rolling without slip
/// (`v = -omega r`): `m a = -F`, `I alpha = F r - mu_r r N` with `a = -alpha r`
/// give the deceleration `a = mu_r g / (1 + I/(m r^2)) = (2/3) mu_r g`.
///
/// The distance to the stop, by energy: the kinetic energy `(3/4) m v0^2`
/// goes into the rolling spring's elastic energy `M_c theta_e / 2` while it
/// loads to the cap `M_c = mu_r r m g` (over `theta_e = M_c / k_r`) and into
/// plastic work `M_c (theta - theta_e)` after it (friction does no work in
/// rolling without slip; the shear spring's energy, `(m a)^2 / 2 ks`, is
/// 2e-4 of it), so `theta = (3/4) m v0^2 / M_c + theta_e / 2` and the disk
/// stops after `r theta = v0^2 / (2 a) + r theta_e / 2`.
#[test]
fn a_rolling_disk_decelerates_at_two_thirds_mu_r_g_and_stops_where_energy_says() {
    let (mu_r, v0) = (0.1, 0.1);
    let mut sim = disk_on_floor(model(0.5, mu_r), [0.0, -G]);
    sim.set_velocities(&[[v0, 0.0]]).unwrap();
    sim.set_angular_velocities(&[-v0 / R]).unwrap();
    let dt = sim.params().time_step;
    let a = 2.0 / 3.0 * mu_r * G;
    let cap = mu_r * R * mass() * G;
    let theta_e = cap / rule_stiffness(mu_r);
    // the spring reaches the cap after theta_e / omega ~ 3 ms; measure the
    // deceleration over 60 ms of the plastic phase from 20 ms on
    let (t1, t2) = (0.02, 0.08);
    sim.run(1).unwrap();
    let balance = sim.energy().balance();
    sim.run((t1 / dt).round() as u64 - 1).unwrap();
    let v1 = sim.particles().velocity[0][0];
    let t1 = sim.time();
    sim.run(((t2 - t1) / dt).round() as u64).unwrap();
    let v2 = sim.particles().velocity[0][0];
    let measured = (v1 - v2) / (sim.time() - t1);
    assert!(
        (measured / a - 1.0).abs() < 2e-4,
        "deceleration {measured}, expected (2/3) mu_r g = {a}"
    );
    // rolling without slip all along
    let w = sim.particles().angular_velocity[0];
    assert!((v2 + w * R).abs() < 1e-3 * v2, "v {v2}, omega r {}", w * R);
    // on to the stop: the first step the disk's velocity is no longer positive
    let x0 = 0.0;
    while sim.particles().velocity[0][0] > 0.0 {
        sim.run(1).unwrap();
    }
    let distance = sim.particles().position[0][0] - x0;
    let expected = v0 * v0 / (2.0 * a) + R * theta_e / 2.0;
    assert!(
        (distance / expected - 1.0).abs() < 1e-3,
        "stopped after {distance} m, expected {expected}"
    );
    // (later than v0 / a by the slower start while the spring loads, ~1 %)
    let time = sim.time();
    assert!((time / (v0 / a) - 1.0).abs() < 0.02, "stopped at {time} s");
    // the ledger balances, the rolling moment's plastic work booked in its line
    let e = sim.energy();
    assert!(e.rolling_dissipated > 0.9 * cap * (distance / R - theta_e));
    let drift = e.balance() - balance;
    assert!(
        drift.abs() < 1e-5 * 0.75 * mass() * v0 * v0,
        "{drift} {e:?}"
    );
}

/// A disk on an incline of angle `theta` (gravity tilted, `g (sin, -cos)`,
/// the floor flat): at rest it needs a friction force `m g sin(theta)` at the
/// contact, whose moment about the centre `r m g sin(theta)` the rolling
/// moment must hold, against the cap `mu_r r N = mu_r r m g cos(theta)`: it
/// stays at rest for `tan(theta) <= mu_r` (with enough sliding friction,
/// `tan(theta) < mu`). Above, it rolls with the moment at the cap:
/// `a = g (sin(theta) - mu_r cos(theta)) / (1 + I/(m r^2))`.
#[test]
fn a_disk_on_an_incline_holds_up_to_tan_theta_mu_r_and_rolls_above() {
    let mu_r: f64 = 0.2;
    // 5 % below the threshold: held, after the rolling spring's elastic
    // rotation `r m g sin(theta) / k_r` (the rolling dashpot lets it settle;
    // the first swing overshoots the cap and rolls a little further), with
    // the moment of the friction force held by the rolling spring exactly
    let theta = (0.95 * mu_r).atan();
    let mut m = model(0.5, mu_r);
    m.rolling_damping_ratio = 0.5;
    let gravity = [G * theta.sin(), -G * theta.cos()];
    let mut sim = disk_on_floor(m, gravity);
    let dt = sim.params().time_step;
    sim.run((0.5 / dt) as u64).unwrap();
    let p = sim.particles();
    let elastic = R * mass() * G * theta.sin() / rule_stiffness(mu_r) * R;
    let (x, v) = (p.position[0][0], p.velocity[0][0]);
    assert!(
        x > 0.0 && x < 3.0 * elastic,
        "moved {x} m (elastic {elastic})"
    );
    assert!(v.abs() < 1e-9, "still moving at {v}");
    let spring = sim.neighbors().wall_pairs.history.records[0][1];
    let needed = R * mass() * G * theta.sin();
    assert!(
        (spring / needed - 1.0).abs() < 1e-6,
        "moment {spring}, needed {needed}"
    );
    // 5 % above: it rolls at the cap's acceleration
    let theta = (1.05 * mu_r).atan();
    let gravity = [G * theta.sin(), -G * theta.cos()];
    let mut sim = disk_on_floor(model(0.5, mu_r), gravity);
    let a = G * (theta.sin() - mu_r * theta.cos()) / 1.5;
    sim.run((0.05 / dt) as u64).unwrap();
    let (v1, t1) = (sim.particles().velocity[0][0], sim.time());
    sim.run((0.25 / dt) as u64).unwrap();
    let measured = (sim.particles().velocity[0][0] - v1) / (sim.time() - t1);
    assert!(
        (measured / a - 1.0).abs() < 1e-5,
        "acceleration {measured}, expected {a}"
    );
}

/// The elastic regime: a disk on a frictionless floor (`mu = 0`: no shear
/// force, so its rotation is free of its translation and it turns about its
/// own centre) with a rolling spring below its cap obeys `I theta'' = -k_r
/// theta`: its angular velocity oscillates at `sqrt(k_r / I)`, `I = m r^2 / 2`
/// (on a rough floor it would turn about the contact point, `I + m r^2`).
/// Leapfrog's period error, `(Omega dt)^2 / 24`, is 7e-6 here (measured: 7.4e-6).
#[test]
fn the_elastic_rolling_spring_oscillates_at_sqrt_k_r_over_i() {
    let mu_r: f64 = 0.1;
    let mut sim = disk_on_floor(model(0.0, mu_r), [0.0, -G]);
    let omega = (rule_stiffness(mu_r) / inertia()).sqrt();
    // amplitude a tenth of the cap's rotation: theta_max = w0 / Omega
    let theta_cap = mu_r * R * mass() * G / rule_stiffness(mu_r);
    sim.set_angular_velocities(&[0.1 * theta_cap * omega])
        .unwrap();
    // the times omega changes sign over five periods
    let mut crossings = Vec::new();
    let mut last = sim.particles().angular_velocity[0];
    let period = 2.0 * std::f64::consts::PI / omega;
    while sim.time() < 5.2 * period {
        sim.run(1).unwrap();
        let w = sim.particles().angular_velocity[0];
        if (w > 0.0) != (last > 0.0) {
            // linear interpolation of the crossing (velocities at half steps)
            let dt = sim.params().time_step;
            crossings.push(sim.time() - dt * w.abs() / (w - last).abs());
        }
        last = w;
    }
    assert!(crossings.len() >= 10, "{crossings:?}");
    let measured =
        2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    assert!(
        (measured / period - 1.0).abs() < 1e-4,
        "period {measured}, expected 2 pi sqrt(I / k_r) = {period}"
    );
    assert_eq!(sim.energy().rolling_dissipated, 0.0);
}

/// A packing with rolling resistance gives the same bits on 1 and 2 threads,
/// and with the four-pair lanes or the scalar loop (two models, one with a
/// rolling dashpot: the lanes' several-model variant with the dashpot).
#[test]
fn rolling_resistance_gives_the_same_bits_on_one_and_two_threads_and_without_lanes() {
    let run = |threads: usize, simd: bool| {
        let mut sim = boxed_packing(60, 0.5, 5, threads);
        let mut m = *sim.materials().get(0, 0);
        m.rolling_friction = 0.3;
        m.rolling_damping_ratio = 0.2;
        sim.set_contact_model(0, 0, m).unwrap();
        let mut w = *sim.materials().get(0, 1);
        w.rolling_friction = 0.1;
        sim.set_contact_model(0, 1, w).unwrap();
        sim.set_simd(simd);
        sim.set_wall_velocity(2, [0.02, -0.002]).unwrap();
        sim.run(400).unwrap();
        assert!(
            sim.neighbors().build_count > 1,
            "the rebuild carried the records"
        );
        let p = sim.particles();
        let mut bits: Vec<u64> = p.angular_velocity.iter().map(|w| w.to_bits()).collect();
        bits.extend(p.position.iter().flat_map(|x| x.map(f64::to_bits)));
        let records = &sim.neighbors().pairs.history.records;
        bits.extend(records.iter().flat_map(|r| r.map(f64::to_bits)));
        let e = sim.energy();
        bits.extend([e.elastic, e.rolling_dissipated, e.friction_dissipated].map(f64::to_bits));
        assert!(e.rolling_dissipated > 0.0);
        assert!(records.iter().any(|r| r[1] != 0.0));
        bits
    };
    let reference = run(1, true);
    assert_eq!(run(2, true), reference, "2 threads");
    assert_eq!(run(1, false), reference, "scalar loop");
}

/// A periodic packing in simple shear whose one contact model (no normal or
/// shear dashpot) has rolling resistance: the four-pair lanes run with their
/// rolling law (the single-model, deforming-cell variant), with and without
/// the rolling dashpot. The same bits as the scalar loop and on 2 threads: the
/// motion, every record (shear and rolling springs), the contact list and the
/// ledger.
#[test]
fn the_four_pair_lanes_with_rolling_resistance_give_the_scalar_loops_bits() {
    for rolling_damping_ratio in [0.0, 0.3] {
        let run = |threads: usize, simd: bool| {
            let grid = dense_periodic(18, 1.0e-3, 0.5, 21, threads);
            let p = grid.particles();
            let mut m = ContactModel::linear(KN, KN, 0.5);
            m.rolling_friction = 0.2;
            m.rolling_damping_ratio = rolling_damping_ratio;
            let particles =
                Particles::new(p.position.clone(), p.radius.clone(), vec![DENSITY]).unwrap();
            let dt = grid.params().time_step;
            let mut sim = Simulation::new(particles, m, dt, threads).unwrap();
            let mut cell = grid.cell().cloned().unwrap();
            cell.velocity_gradient = [[0.0, 0.4], [0.0, 0.0]];
            sim.set_cell(Some(cell)).unwrap();
            assert!(sim.materials().single_undamped_model().is_some());
            set_random_motion(
                &mut sim,
                &mut Rng::new(3),
                (-0.02, 0.02),
                (-0.02, 0.02),
                (-20.0, 20.0),
            );
            let used = sim.set_simd(simd);
            sim.run(600).unwrap();
            let mut bits: Vec<u64> = Vec::new();
            let p = sim.particles();
            bits.extend(p.angular_velocity.iter().map(|w| w.to_bits()));
            bits.extend(p.position.iter().flat_map(|x| x.map(f64::to_bits)));
            let records = &sim.neighbors().pairs.history.records;
            bits.extend(records.iter().flat_map(|r| r.map(f64::to_bits)));
            let loaded = records.iter().filter(|r| r[1] != 0.0).count();
            assert!(loaded > 100, "{loaded} rolling springs");
            let e = sim.energy();
            bits.extend(
                [
                    e.elastic,
                    e.kinetic,
                    e.rolling_dissipated,
                    e.friction_dissipated,
                ]
                .map(f64::to_bits),
            );
            assert!(e.rolling_dissipated > 0.0);
            bits.extend(contact_list_bits(&mut sim));
            (bits, used)
        };
        let (reference, used) = run(1, true);
        if !used {
            eprintln!("no AVX2 on this processor: the scalar loop against itself");
        }
        assert!(
            run(1, false).0 == reference,
            "scalar loop, eta_r {rolling_damping_ratio}"
        );
        assert!(
            run(2, true).0 == reference,
            "2 threads, eta_r {rolling_damping_ratio}"
        );
    }
}

/// The critical time step counts the rolling spring in the rotational
/// stiffness: `sqrt(I / (k_s r^2 + k_r))` for a disk on a wall.
#[test]
fn the_critical_time_step_counts_the_rolling_stiffness() {
    let mut m = model(0.5, 0.1);
    let plain = disk_on_floor(m, [0.0, -G]).critical_time_step(1.0).unwrap();
    let k_r = 10.0 * KN * R * R;
    m.rolling_stiffness = k_r;
    let dt = disk_on_floor(m, [0.0, -G]).critical_time_step(1.0).unwrap();
    let expected = (inertia() / (KN * R * R + k_r)).sqrt();
    assert!((dt / expected - 1.0).abs() < 1e-12, "{dt} vs {expected}");
    assert!(dt < plain);
}

/// The springs' catch-up (which every change of the motion goes through)
/// gives the rolling spring the last step's increment `-k_r omega dt` as the
/// next force evaluation would, and that evaluation then adds none.
#[test]
fn the_catch_up_gives_the_rolling_spring_its_increment() {
    let mu_r = 0.5; // a high cap: the spring stays elastic
    let mut sim = disk_on_floor(model(0.5, mu_r), [0.0, -G]);
    sim.set_velocities(&[[0.01, 0.0]]).unwrap();
    sim.set_angular_velocities(&[-0.01 / R]).unwrap();
    sim.run(20).unwrap();
    let before = sim.neighbors().wall_pairs.history.records[0][1];
    let w = sim.particles().angular_velocity[0];
    let dt = sim.params().time_step;
    assert!(before > 0.0 && w < 0.0, "{before} {w}");
    sim.catch_up_shear_springs();
    let after = sim.neighbors().wall_pairs.history.records[0][1];
    let k_r = grainlab_core::law::rolling::RollingSpring::stiffness(
        sim.materials().get(0, 1),
        sim.materials().get(0, 1).normal_stiffness,
        R,
    );
    assert_eq!(after, before - k_r * w * dt);
    // a change of the motion now (the springs current) adds no second increment
    let v = sim.particles().velocity.clone();
    sim.set_velocities(&v).unwrap();
    assert_eq!(sim.neighbors().wall_pairs.history.records[0][1], after);
}
