//! Conservation laws: energy in a dense frictionless packing without damping,
//! linear momentum without walls.
mod common;
use common::*;
use grainlab_core::ContactModel;

/// Gives the packing random velocities whose kinetic energy equals its elastic energy.
fn agitate(sim: &mut grainlab_core::Simulation, spin: bool) {
    sim.run(1).unwrap();
    let elastic = sim.energy().elastic;
    let mut rng = Rng::new(5);
    // the setters take the user's (external) order, the engine keeps its own
    let p = sim.particles();
    let (mass, inertia, radius) = (
        sim.to_external(&p.mass),
        sim.to_external(&p.inertia),
        sim.to_external(&p.radius),
    );
    let n = mass.len();
    let (mut velocity, mut omega) = (vec![[0.0; 2]; n], vec![0.0; n]);
    let mut kinetic = 0.0;
    for k in 0..n {
        velocity[k] = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        omega[k] = if spin {
            rng.uniform(-1.0, 1.0) / radius[k]
        } else {
            0.0
        };
        let v = velocity[k];
        kinetic +=
            0.5 * mass[k] * (v[0] * v[0] + v[1] * v[1]) + 0.5 * inertia[k] * omega[k].powi(2);
    }
    let s = (elastic / kinetic).sqrt();
    for k in 0..n {
        velocity[k] = [velocity[k][0] * s, velocity[k][1] * s];
        omega[k] *= s;
    }
    sim.set_velocities(&velocity).unwrap();
    sim.set_angular_velocities(&omega).unwrap();
}

#[test]
fn energy_is_conserved_in_a_dense_frictionless_packing() {
    // The common 4,000-disk packing (Z ~ 4), no damping, dt = 0.2 sqrt(m_min/kn):
    // leapfrog keeps kinetic + elastic energy within 0.1% over 10,000 steps.
    let mut sim = bench_packing(0.0, 0.2, 1);
    agitate(&mut sim, false);
    sim.run(1).unwrap();
    let e0 = mechanical_energy(&sim);
    assert!(
        sim.measurements().contact_count > 7000,
        "not dense: {} contacts",
        sim.measurements().contact_count
    );
    let mut worst = 0.0f64;
    for _ in 0..100 {
        sim.run(100).unwrap();
        worst = worst.max((mechanical_energy(&sim) / e0 - 1.0).abs());
    }
    assert!(worst < 1e-3, "energy drift {worst}");
    let e = sim.energy();
    assert!(
        e.kinetic > 0.1 * e0 && e.elastic > 0.1 * e0,
        "energy did not move between forms"
    );
}

#[test]
fn energy_ledger_balances_with_friction_and_damping() {
    // kinetic + elastic + dissipated (friction, local damping) stays constant.
    let mut sim = bench_packing(0.5, 0.2, 2);
    agitate(&mut sim, true);
    let mut params = sim.params();
    params.local_damping = 0.3;
    sim.set_params(params).unwrap();
    sim.run(1).unwrap();
    let b0 = sim.energy().balance();
    sim.run(3000).unwrap();
    let e = sim.energy();
    assert!(
        e.friction_dissipated > 0.01 * b0 && e.damping_dissipated > 0.01 * b0,
        "{e:?}"
    );
    assert!(
        (e.balance() / b0 - 1.0).abs() < 2e-3,
        "balance drift {}",
        e.balance() / b0 - 1.0
    );
}

#[test]
fn energy_ledger_balances_with_viscous_contact_damping() {
    // kinetic + elastic + friction + viscous (normal and shear dashpots) stays
    // constant: a dashpot that booked its work with the wrong sign would show
    // up here as a drift of twice the viscous dissipation. The dashpots' work is
    // booked with the half-step velocity, an estimate of first order in dt:
    // measured drift 2.3 % of the viscous dissipation at dt = 0.1 sqrt(m/kn),
    // 1.2 % at 0.05.
    let mut sim = bench_packing(0.5, 0.1, 1);
    let mut model = ContactModel::linear(KN, KN, 0.5);
    model.normal_damping_ratio = 0.2;
    model.shear_damping_ratio = 0.2;
    sim.set_contact_model(0, 0, model).unwrap();
    agitate(&mut sim, true);
    sim.run(1).unwrap();
    let b0 = sim.energy().balance();
    sim.run(3000).unwrap();
    let e = sim.energy();
    assert!(e.viscous_dissipated > 0.05 * b0, "{e:?}");
    assert!(
        (e.balance() - b0).abs() < 0.05 * e.viscous_dissipated,
        "balance drift {} with viscous dissipation {}",
        e.balance() / b0 - 1.0,
        e.viscous_dissipated / b0
    );
}

#[test]
fn energy_ledger_balances_with_moving_and_servo_walls() {
    // A dense frictional box squeezed by its top wall at constant velocity while
    // its right wall holds a stress by servo, with local damping and a bonded
    // chain, at dt = 0.1 sqrt(m_min/kn): the walls' work, booked with the
    // trapezoid of the forces before and after each step's displacement, balances
    // kinetic + elastic energy + dissipation to 1e-4 of the work done.
    use grainlab_core::{ServoControl, WallControl};
    let mut sim = boxed_packing(16, 0.5, 8, 1);
    let l = 16.0e-3;
    sim.run(2000).unwrap(); // settle in the fixed box first
    sim.set_wall_velocity(2, [0.0, -2.0e-3]).unwrap();
    let servo = ServoControl {
        target_stress: 2.0e6,
        loaded_length: l,
        relaxation: 0.5,
        max_speed: 0.01,
    };
    sim.set_wall_control(1, WallControl::Servo(servo)).unwrap();
    sim.run(1).unwrap();
    let b0 = sim.energy().balance();
    sim.run(3000).unwrap();
    let e = sim.energy();
    assert!(e.wall_work > 0.5 * b0, "{e:?}");
    assert!(
        e.friction_dissipated > 0.01 * e.wall_work && e.damping_dissipated > 0.01 * e.wall_work
    );
    let drift = (e.balance() - b0) / e.wall_work;
    eprintln!("balance drift {drift:.3e} of the wall work");
    assert!(
        drift.abs() < 1e-4,
        "balance drift {drift:.3e} of the wall work; {e:?}"
    );
}

#[test]
fn momentum_is_conserved_without_walls() {
    // Newton's third law in every contact: total linear momentum is constant.
    let mut sim = dense_periodic(16, 1.0e-3, 0.9, 21, 2);
    let mut rng = Rng::new(1);
    set_random_motion(
        &mut sim,
        &mut rng,
        (-0.01, 0.01),
        (-0.01, 0.01),
        (-5.0, 5.0),
    );
    let momentum = |sim: &grainlab_core::Simulation| {
        let p = &sim.particles();
        (0..p.len()).fold([0.0, 0.0], |acc, k| {
            [
                acc[0] + p.mass[k] * p.velocity[k][0],
                acc[1] + p.mass[k] * p.velocity[k][1],
            ]
        })
    };
    let scale: f64 = (0..sim.particles().len())
        .map(|k| sim.particles().mass[k] * 0.01)
        .sum();
    let p0 = momentum(&sim);
    sim.run(3000).unwrap();
    let p1 = momentum(&sim);
    for c in 0..2 {
        assert!(
            (p1[c] - p0[c]).abs() < 1e-12 * scale,
            "momentum component {c}: {} -> {}",
            p0[c],
            p1[c]
        );
    }
}
