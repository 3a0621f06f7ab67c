//! The common throughput case (benchmarks/README): 4,000 dense disks, Table 1
//! stiffness and friction, no damping, 100 warm-up steps then 20,000 timed
//! steps of constant-area pure shear of the periodic cell.
//!
//! Usage: `cargo run --release --example throughput -- [threads] [steps] [path]
//! [--rolling-friction=MU] [--hertz-mindlin=E]` (the options, anywhere among the
//! arguments: `--rolling-friction` gives the contact model rolling resistance
//! `mu_r = MU` with its stiffness from the rule, 0, the default, leaves it off;
//! `--hertz-mindlin` makes the law Hertz-Mindlin with Young's modulus `E` (Pa),
//! Poisson ratio 0.25 and restitution 0.5, at the same time step).
//! Prints one line: `particle_steps_per_s=<value> threads=<n> ...`.
use grainlab_core::{ContactModel, Particles, PeriodicCell, Simulation};
use std::time::Instant;

fn main() {
    const ROLLING: &str = "--rolling-friction=";
    const HERTZ: &str = "--hertz-mindlin=";
    let all: Vec<String> = std::env::args().collect();
    let option = |name: &str| all.iter().find_map(|a| a.strip_prefix(name));
    let rolling_friction: f64 =
        option(ROLLING).map_or(0.0, |s| s.parse().expect("--rolling-friction=MU, MU >= 0"));
    let youngs_modulus: Option<f64> =
        option(HERTZ).map(|s| s.parse().expect("--hertz-mindlin=E, E > 0 in Pa"));
    let args: Vec<String> = all
        .iter()
        .filter(|a| !a.starts_with(ROLLING) && !a.starts_with(HERTZ))
        .cloned()
        .collect();
    let threads: usize = args.get(1).map_or(1, |s| s.parse().expect("threads"));
    let steps: u64 = args.get(2).map_or(20_000, |s| s.parse().expect("steps"));
    let default_path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../benchmarks/data/dense-4000-disks.xyr"
    );
    let path = args.get(3).map_or(default_path.to_string(), |s| s.clone());
    let text = std::fs::read_to_string(&path).expect("packing file");
    let mut lines = text.lines();
    let side: f64 = lines.next().unwrap().trim().parse().unwrap();
    let (mut pos, mut rad) = (Vec::new(), Vec::new());
    for line in lines.filter(|s| !s.trim().is_empty()) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        pos.push([v[0], v[1]]);
        rad.push(v[2]);
    }
    let n = pos.len();
    let particles = Particles::new(pos, rad, vec![2.0e8]).unwrap();
    let mut model = match youngs_modulus {
        Some(e) => ContactModel::hertz_mindlin(e, 0.25, 0.5, 0.9),
        None => ContactModel::linear(8.45e7, 8.45e7, 0.9),
    };
    model.rolling_friction = rolling_friction;
    let mut sim = Simulation::new(particles, model, 1.36e-4, threads).unwrap();
    let mut cell = PeriodicCell::rectangle([0.0, 0.0], side, side, [true, true]).unwrap();
    let rate = 3.676e-3;
    cell.velocity_gradient = [[-rate, 0.0], [0.0, rate]];
    sim.set_cell(Some(cell)).unwrap();
    sim.run(100).unwrap();
    let z0 = 2.0 * sim.measurements().contact_count as f64 / n as f64;
    let builds0 = sim.neighbors().build_count;
    let start = Instant::now();
    sim.run(steps).unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let z1 = 2.0 * sim.measurements().contact_count as f64 / n as f64;
    println!(
        "particle_steps_per_s={:.6e} threads={threads} rolling_friction={rolling_friction} law={} seconds={elapsed:.4} z_start={z0:.3} z_end={z1:.3} rebuilds={}",
        n as f64 * steps as f64 / elapsed,
        model.law.name(),
        sim.neighbors().build_count - builds0
    );
}
