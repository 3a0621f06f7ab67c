//! Head-on collision of two equal disks against the analytical linear-spring solution.
mod common;
use common::*;
use grainlab_core::{ContactModel, StepParameters};

/// Runs a head-on collision at closing speed `2 v0`; returns (contact duration, restitution).
fn collide(alpha: f64) -> (f64, f64) {
    let r = 1.0e-3;
    let v0 = 0.05;
    let model = ContactModel::linear(KN, KN, 0.5);
    let m = DENSITY * std::f64::consts::PI * r * r;
    let m_star = 0.5 * m;
    // contact duration pi sqrt(m*/kn); 2000 steps per contact keeps O(dt) errors < 0.1%
    let t_c = std::f64::consts::PI * (m_star / KN).sqrt();
    let dt = t_c / 2000.0;
    let mut sim = disks(
        vec![[0.0, 0.0], [2.0 * r + 1e-6, 0.0]],
        vec![r, r],
        model,
        dt,
    );
    sim.set_params(StepParameters {
        time_step: dt,
        local_damping: alpha,
        gravity: [0.0; 2],
        max_overlap_ratio: 0.9,
    })
    .unwrap();
    sim.set_velocities(&[[v0, 0.0], [-v0, 0.0]]).unwrap();
    let (mut start, mut end) = (None, None);
    for _ in 0..20_000 {
        sim.run(1).unwrap();
        let touching = sim.measurements().contact_count > 0;
        if touching && start.is_none() {
            start = Some(sim.time() - dt);
        }
        if !touching && start.is_some() && end.is_none() {
            end = Some(sim.time() - dt);
            break;
        }
    }
    let duration = end.unwrap() - start.unwrap();
    let v = sim.to_external(&sim.particles().velocity); // the engine keeps its own order
    let v_after = v[1][0] - v[0][0];
    (duration, v_after / (2.0 * v0))
}

#[test]
fn elastic_collision_duration_and_restitution() {
    // t_c = pi sqrt(m*/kn), e = 1 without damping
    let r = 1.0e-3;
    let m = DENSITY * std::f64::consts::PI * r * r;
    let t_c = std::f64::consts::PI * (0.5 * m / KN).sqrt();
    let (duration, e) = collide(0.0);
    assert!(
        (duration / t_c - 1.0).abs() < 0.005,
        "duration {duration} vs {t_c}"
    );
    assert!((e - 1.0).abs() < 0.005, "restitution {e}");
}

#[test]
fn local_damping_restitution() {
    // e = sqrt((1 - alpha) / (1 + alpha)) for PFC local damping
    for alpha in [0.8, 0.7] {
        let (_, e) = collide(alpha);
        let expected = ((1.0 - alpha) / (1.0 + alpha)).sqrt();
        assert!(
            (e / expected - 1.0).abs() < 0.01,
            "alpha {alpha}: e = {e}, expected {expected}"
        );
    }
}
