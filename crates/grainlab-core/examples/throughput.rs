//! The common throughput case (benchmarks/README): 4,000 dense disks, Table 1
//! stiffness and friction, no damping, 100 warm-up steps then 20,000 timed
//! steps of constant-area pure shear of the periodic cell.
//!
//! Usage: `cargo run --release --example throughput -- [threads] [steps] [path]
//! [--rolling-friction=MU] [--hertz-mindlin=E] [--trimers]` (the options,
//! anywhere among the arguments: `--rolling-friction` gives the contact model
//! rolling resistance `mu_r = MU` with its stiffness from the rule, 0, the
//! default, leaves it off; `--hertz-mindlin` makes the law Hertz-Mindlin with
//! Young's modulus `E` (Pa), Poisson ratio 0.25 and restitution 0.5, at the
//! same time step; `--trimers` makes rigid clumps of the disks, three touching
//! disks each (`touching_triples`), the disks left over staying bodies of
//! their own: the same pebbles, the same contacts but those inside a clump).
//! Prints one line: `particle_steps_per_s=<value> threads=<n> ...`, per pebble.
use grainlab_core::{BodySpec, ContactModel, Particles, PeriodicCell, Simulation};
use std::time::Instant;

fn main() {
    const ROLLING: &str = "--rolling-friction=";
    const HERTZ: &str = "--hertz-mindlin=";
    const TRIMERS: &str = "--trimers";
    let all: Vec<String> = std::env::args().collect();
    let option = |name: &str| all.iter().find_map(|a| a.strip_prefix(name));
    let rolling_friction: f64 =
        option(ROLLING).map_or(0.0, |s| s.parse().expect("--rolling-friction=MU, MU >= 0"));
    let youngs_modulus: Option<f64> =
        option(HERTZ).map(|s| s.parse().expect("--hertz-mindlin=E, E > 0 in Pa"));
    let args: Vec<String> = all
        .iter()
        .filter(|a| !a.starts_with(ROLLING) && !a.starts_with(HERTZ) && *a != TRIMERS)
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
    let trimers = all
        .iter()
        .any(|a| a == TRIMERS)
        .then(|| touching_triples(&pos, &rad, side));
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
    let clumped = trimers.as_ref().map_or(0, |t| 3 * t.len());
    if let Some(bodies) = trimers {
        sim.add_bodies(&bodies).unwrap();
    }
    sim.run(100).unwrap();
    let z0 = 2.0 * sim.measurements().contact_count as f64 / n as f64;
    let builds0 = sim.neighbors().build_count;
    let start = Instant::now();
    sim.run(steps).unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let z1 = 2.0 * sim.measurements().contact_count as f64 / n as f64;
    println!(
        "particle_steps_per_s={:.6e} threads={threads} rolling_friction={rolling_friction} law={} pebbles_in_clumps={clumped} seconds={elapsed:.4} z_start={z0:.3} z_end={z1:.3} rebuilds={}",
        n as f64 * steps as f64 / elapsed,
        model.law.name(),
        sim.neighbors().build_count - builds0
    );
}

/// Trimers of touching disks (periodic square cell of side `side`), greedily,
/// the disks with fewest neighbours first: each disk not yet taken with two untaken neighbours that
/// touch each other (a triangle), else between two untaken neighbours, else
/// with an untaken neighbour and one of that one's (bent chains of three).
fn touching_triples(pos: &[[f64; 2]], rad: &[f64], side: f64) -> Vec<BodySpec> {
    let n = pos.len();
    let touch = |i: usize, j: usize| {
        let mut d = [pos[j][0] - pos[i][0], pos[j][1] - pos[i][1]];
        for x in d.iter_mut() {
            *x -= side * (*x / side).round();
        }
        (d[0] * d[0] + d[1] * d[1]).sqrt() < rad[i] + rad[j]
    };
    let neighbours: Vec<Vec<usize>> = (0..n)
        .map(|i| (0..n).filter(|&j| j != i && touch(i, j)).collect())
        .collect();
    // the disks with fewest neighbours first, so fewer are left over
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| neighbours[i].len());
    let mut taken = vec![false; n];
    let mut bodies = Vec::new();
    for i in order {
        if taken[i] {
            continue;
        }
        let free = |q: &usize| !taken[*q];
        let near: Vec<usize> = neighbours[i].iter().copied().filter(free).collect();
        let triangle = near.iter().enumerate().find_map(|(a, &j)| {
            near[a + 1..]
                .iter()
                .find(|&&k| touch(j, k))
                .map(|&k| (j, k))
        });
        let chain = || {
            near.iter().find_map(|&j| {
                neighbours[j]
                    .iter()
                    .find(|&&k| k != i && !taken[k])
                    .map(|&k| (j, k))
            })
        };
        let middle = (near.len() >= 2).then(|| (near[0], near[1]));
        if let Some((j, k)) = triangle.or(middle).or_else(chain) {
            for q in [i, j, k] {
                taken[q] = true;
            }
            bodies.push(BodySpec {
                pebbles: vec![i, j, k],
                angle: 0.0,
                given: None,
            });
        }
    }
    bodies
}
