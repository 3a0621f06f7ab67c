//! Disk-wall impacts, rolling, and servo control against analytical results.
mod common;
use common::*;
use grainlab_core::{ContactModel, ServoControl, StepParameters, Wall, WallControl, WallShape};

const R: f64 = 1.0e-3;

fn mass() -> f64 {
    DENSITY * std::f64::consts::PI * R * R
}

fn floor_sim(model: ContactModel, dt: f64, gravity: f64, y0: f64) -> grainlab_core::Simulation {
    let mut sim = disks(vec![[0.0, y0]], vec![R], model, dt);
    sim.set_params(StepParameters {
        time_step: dt,
        local_damping: 0.0,
        gravity: [0.0, -gravity],
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
    sim
}

#[test]
fn normal_impact_on_a_wall() {
    // single disk on a rigid wall: t_c = pi sqrt(m/kn), e = 1
    let t_c = std::f64::consts::PI * (mass() / KN).sqrt();
    let dt = t_c / 2000.0;
    let mut sim = floor_sim(ContactModel::linear(KN, KN, 0.3), dt, 0.0, R + 1e-7);
    sim.set_velocities(&[[0.0, -0.1]]).unwrap();
    let (mut start, mut end) = (None, None);
    for _ in 0..10_000 {
        sim.run(1).unwrap();
        let touching = sim.walls()[0].contact_count > 0;
        if touching && start.is_none() {
            start = Some(sim.time() - dt);
        } else if !touching && start.is_some() {
            end = Some(sim.time() - dt);
            break;
        }
    }
    let duration = end.unwrap() - start.unwrap();
    assert!(
        (duration / t_c - 1.0).abs() < 0.005,
        "duration {duration} vs {t_c}"
    );
    let e = sim.particles().velocity[0][1] / 0.1;
    assert!((e - 1.0).abs() < 0.005, "restitution {e}");
}

#[test]
fn oblique_impact_in_gross_sliding() {
    // Sliding throughout (v_t - 3 mu (1+e) v_n > 0): tangential impulse mu (1+e) m v_n, so
    // v_t' = v_t - mu (1+e) v_n and, with I = m r^2 / 2, omega' = -2 mu (1+e) v_n / r.
    let mu = 0.1;
    let (vt, vn) = (0.05, 0.05);
    let t_c = std::f64::consts::PI * (mass() / KN).sqrt();
    let dt = t_c / 4000.0;
    let mut sim = floor_sim(ContactModel::linear(KN, KN, mu), dt, 0.0, R + 1e-7);
    sim.set_velocities(&[[vt, -vn]]).unwrap();
    let mut touched = false;
    for _ in 0..20_000 {
        sim.run(1).unwrap();
        let touching = sim.walls()[0].contact_count > 0;
        touched |= touching;
        if touched && !touching {
            break;
        }
    }
    let v = sim.particles().velocity[0];
    let w = sim.particles().angular_velocity[0];
    let e = v[1] / vn;
    assert!((e - 1.0).abs() < 0.005, "normal restitution {e}");
    let vt_expected = vt - mu * (1.0 + e) * vn;
    let w_expected = -2.0 * mu * (1.0 + e) * vn / R;
    assert!(
        (v[0] / vt_expected - 1.0).abs() < 0.01,
        "v_t' = {} vs {vt_expected}",
        v[0]
    );
    assert!(
        (w / w_expected - 1.0).abs() < 0.01,
        "omega' = {w} vs {w_expected}"
    );
}

#[test]
fn sliding_disk_ends_in_pure_rolling_at_two_thirds_speed() {
    // Friction converts sliding to rolling: v_final = v0 / (1 + I/(m r^2)) = 2/3 v0.
    let g = 9.81;
    let v0 = 0.2;
    let mut model = ContactModel::linear(KN, KN, 0.5);
    model.normal_damping_ratio = 0.3;
    model.shear_damping_ratio = 0.3;
    let t_c = std::f64::consts::PI * (mass() / KN).sqrt();
    let dt = t_c / 50.0;
    let overlap = mass() * g / KN;
    let mut sim = floor_sim(model, dt, g, R - overlap);
    sim.set_velocities(&[[v0, 0.0]]).unwrap();
    // sliding lasts v0 / (3 mu g) ~ 14 ms; run 40 ms
    let steps = (0.04 / dt) as u64;
    sim.run(steps).unwrap();
    let v = sim.particles().velocity[0][0];
    let w = sim.particles().angular_velocity[0];
    assert!(
        (v / (2.0 * v0 / 3.0) - 1.0).abs() < 0.01,
        "final speed {v}, expected {}",
        2.0 * v0 / 3.0
    );
    assert!(
        ((v + w * R) / v).abs() < 0.01,
        "not rolling: v = {v}, omega r = {}",
        w * R
    );
}

#[test]
fn servo_wall_reaches_its_target_stress() {
    // A 12 x 12 grid of disks in a box; the top wall is servo-controlled to 100 kPa.
    let s = 2.0e-3;
    let n = 12;
    let mut rng = Rng::new(7);
    let mut pos = Vec::new();
    let mut rad = Vec::new();
    for a in 0..n {
        for b in 0..n {
            pos.push([(a as f64 + 0.5) * s, (b as f64 + 0.5) * s]);
            rad.push(rng.uniform(0.4, 0.5) * s);
        }
    }
    let particles = grainlab_core::Particles::new(pos, rad, vec![DENSITY]).unwrap();
    let m_min = DENSITY * std::f64::consts::PI * (0.4 * s).powi(2);
    let dt = 0.2 * (m_min / KN).sqrt();
    let mut sim =
        grainlab_core::Simulation::new(particles, ContactModel::linear(KN, KN, 0.5), dt, 1)
            .unwrap();
    sim.set_params(StepParameters {
        time_step: dt,
        local_damping: 0.7,
        gravity: [0.0; 2],
        max_overlap_ratio: 0.5,
    })
    .unwrap();
    let l = n as f64 * s;
    let seg = |a: [f64; 2], b: [f64; 2]| Wall::new(WallShape::Segment { a, b }, 1).unwrap();
    sim.add_wall(seg([0.0, 0.0], [l, 0.0])); // bottom, inward normal +y
    sim.add_wall(seg([l, 0.0], [l, l])); // right, inward -x
    sim.add_wall(seg([0.0, l], [0.0, 0.0])); // left, inward +x
    let top = sim.add_wall(seg([l, l], [0.0, l])); // top, inward -y
    let target = 1.0e5;
    sim.set_wall_control(
        top,
        WallControl::Servo(ServoControl {
            target_stress: target,
            loaded_length: l,
            relaxation: 0.5,
            max_speed: 0.05,
        }),
    )
    .unwrap();
    sim.run(20_000).unwrap();
    let stress = sim.walls()[top].normal_stress(l);
    assert!(
        (stress / target - 1.0).abs() < 0.01,
        "servo stress {stress} vs {target}"
    );
    // static equilibrium: the opposite wall carries the same load
    let bottom = sim.walls()[0].normal_stress(l);
    assert!(
        (bottom / target - 1.0).abs() < 0.02,
        "bottom stress {bottom}"
    );
}
