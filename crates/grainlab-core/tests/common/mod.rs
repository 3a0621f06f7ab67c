//! Builders shared by the integration tests.
#![allow(dead_code)]
use grainlab_core::{ContactModel, Particles, PeriodicCell, Simulation};

/// A tiny deterministic generator (SplitMix64) so tests need no extra crate.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Gives every disk (in the user's order) a velocity uniform in `vx` x `vy`
/// (m/s) and an angular velocity uniform in `omega` (rad/s), drawn per disk
/// in that order.
pub fn set_random_motion(
    sim: &mut Simulation,
    rng: &mut Rng,
    vx: (f64, f64),
    vy: (f64, f64),
    omega: (f64, f64),
) {
    let n = sim.particles().len();
    let (mut v, mut w) = (vec![[0.0; 2]; n], vec![0.0; n]);
    for k in 0..n {
        v[k] = [rng.uniform(vx.0, vx.1), rng.uniform(vy.0, vy.1)];
        w[k] = rng.uniform(omega.0, omega.1);
    }
    sim.set_velocities(&v).unwrap();
    sim.set_angular_velocities(&w).unwrap();
}

pub const KN: f64 = 8.45e7;
pub const DENSITY: f64 = 2.0e8;

/// A jittered square grid of `n_side` x `n_side` disks of spacing `s`, radii
/// uniform in `[0.45 s, 0.56 s]` (neighbours overlap), Table 1's stiffness,
/// dt = 0.1 sqrt(m_min / kn), no cell or walls; returns the generator for more.
fn jittered_grid(
    n_side: usize,
    s: f64,
    friction: f64,
    seed: u64,
    threads: usize,
) -> (Simulation, Rng) {
    let mut rng = Rng::new(seed);
    let mut pos = Vec::new();
    let mut rad = Vec::new();
    for a in 0..n_side {
        for b in 0..n_side {
            pos.push([
                (a as f64 + 0.5 + rng.uniform(-0.05, 0.05)) * s,
                (b as f64 + 0.5 + rng.uniform(-0.05, 0.05)) * s,
            ]);
            rad.push(rng.uniform(0.45, 0.56) * s);
        }
    }
    let particles = Particles::new(pos, rad, vec![DENSITY]).unwrap();
    let m_min = DENSITY * std::f64::consts::PI * (0.45 * s).powi(2);
    let dt = 0.1 * (m_min / KN).sqrt();
    let sim = Simulation::new(
        particles,
        ContactModel::linear(KN, KN, friction),
        dt,
        threads,
    )
    .unwrap();
    (sim, rng)
}

/// A dense, overlapping packing in a periodic square cell: [`jittered_grid`].
pub fn dense_periodic(
    n_side: usize,
    s: f64,
    friction: f64,
    seed: u64,
    threads: usize,
) -> Simulation {
    let (mut sim, _) = jittered_grid(n_side, s, friction, seed, threads);
    let l = n_side as f64 * s;
    sim.set_cell(Some(
        PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap(),
    ))
    .unwrap();
    sim
}

/// Total kinetic + elastic energy as measured by the engine at its last measured step.
pub fn mechanical_energy(sim: &Simulation) -> f64 {
    let e = sim.energy();
    e.kinetic + e.elastic
}

/// Two disks or a disk alone: builds a simulation without walls or cell.
pub fn disks(pos: Vec<[f64; 2]>, rad: Vec<f64>, model: ContactModel, dt: f64) -> Simulation {
    let particles = Particles::new(pos, rad, vec![DENSITY]).unwrap();
    Simulation::new(particles, model, dt, 1).unwrap()
}

/// The common 4,000-disk dense packing (`benchmarks/data/dense-4000-disks.xyr`):
/// first line the side of the square periodic cell, then `x y radius` per disk.
pub fn bench_packing(friction: f64, dt_factor: f64, threads: usize) -> Simulation {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../benchmarks/data/dense-4000-disks.xyr"
    );
    let text = std::fs::read_to_string(path).expect("benchmarks/data/dense-4000-disks.xyr");
    let mut lines = text.lines();
    let l: f64 = lines.next().unwrap().trim().parse().unwrap();
    let (mut pos, mut rad) = (Vec::new(), Vec::new());
    for line in lines.filter(|s| !s.trim().is_empty()) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        pos.push([v[0], v[1]]);
        rad.push(v[2]);
    }
    let r_min = rad.iter().cloned().fold(f64::INFINITY, f64::min);
    let m_min = DENSITY * std::f64::consts::PI * r_min * r_min;
    let dt = dt_factor * (m_min / KN).sqrt();
    let particles = Particles::new(pos, rad, vec![DENSITY]).unwrap();
    let mut sim = Simulation::new(
        particles,
        ContactModel::linear(KN, KN, friction),
        dt,
        threads,
    )
    .unwrap();
    sim.set_cell(Some(
        PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap(),
    ))
    .unwrap();
    sim
}

/// A dense, overlapping packing in a box: a jittered square grid of spacing `s`
/// (radii uniform in `[0.45 s, 0.56 s]`) between four segment walls at its edges
/// (ids 0 bottom, 1 right, 2 top, 3 left, all touched by the outer disks), the
/// first column (`0..n_side`, bottom to top) bonded into a chain like a membrane,
/// random velocities and spins (full-step values), local damping 0.3.
pub fn boxed_packing(n_side: usize, friction: f64, seed: u64, threads: usize) -> Simulation {
    use grainlab_core::{StepParameters, Wall, WallShape};
    let s = 1.0e-3;
    let (mut sim, mut rng) = jittered_grid(n_side, s, friction, seed, threads);
    let dt = sim.params().time_step;
    sim.set_params(StepParameters {
        time_step: dt,
        local_damping: 0.3,
        gravity: [0.0; 2],
        max_overlap_ratio: 0.5,
    })
    .unwrap();
    let l = n_side as f64 * s;
    let corners = [[0.0, 0.0], [l, 0.0], [l, l], [0.0, l]];
    for k in 0..4 {
        let wall = Wall::new(
            WallShape::Segment {
                a: corners[k],
                b: corners[(k + 1) % 4],
            },
            1,
        )
        .unwrap();
        sim.add_wall(wall);
    }
    for b in 0..n_side - 1 {
        sim.add_bond(b, b + 1, 0.1 * KN, 0.1 * KN, None).unwrap();
    }
    set_random_motion(
        &mut sim,
        &mut rng,
        (-0.02, 0.02),
        (-0.02, 0.02),
        (-20.0, 20.0),
    );
    sim
}

/// The contact list's every field, as bits.
pub fn contact_list_bits(sim: &mut Simulation) -> Vec<u64> {
    let c = sim.contacts().unwrap();
    let mut bits: Vec<u64> = Vec::new();
    for k in 0..c.i.len() {
        bits.extend([
            c.i[k] as u64,
            c.j[k] as u64,
            c.sliding[k] as u64,
            c.bonded[k] as u64,
        ]);
        let v = [
            c.point[k][0],
            c.point[k][1],
            c.normal[k][0],
            c.normal[k][1],
            c.overlap[k],
            c.normal_force[k],
            c.shear_force[k],
            c.rolling_moment[k],
        ];
        bits.extend(v.iter().map(|x| x.to_bits()));
    }
    bits
}
