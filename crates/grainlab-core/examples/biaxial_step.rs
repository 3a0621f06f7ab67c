//! Shear steps of a saved engine state (benchmarks/biaxial_step.py writes the
//! biaxial test's state at the start of shear), from Rust alone, so that two
//! builds of the engine can be compared on it.
//!
//! Usage: `cargo run --release --example biaxial_step -- STATE [threads] [steps] [warmup]`.
//! Prints one line: `particle_steps_per_s=<value> threads=<n> ...`.
use grainlab_core::Simulation;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("the state file");
    let threads: usize = args.get(2).map_or(1, |s| s.parse().expect("threads"));
    let steps: u64 = args.get(3).map_or(2000, |s| s.parse().expect("steps"));
    let warmup: u64 = args.get(4).map_or(200, |s| s.parse().expect("warmup"));
    let bytes = std::fs::read(path).expect("state file");
    let mut sim = Simulation::from_bytes(&bytes).expect("an engine state");
    sim.set_threads(threads).expect("threads");
    let n = sim.particles().len();
    sim.run(warmup).expect("warm-up steps");
    let builds0 = sim.neighbors().build_count;
    let start = Instant::now();
    sim.run(steps).expect("timed steps");
    let elapsed = start.elapsed().as_secs_f64();
    let p = sim.particles();
    // a fingerprint of the final state, to check that two builds agree bitwise
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for x in p
        .position
        .iter()
        .flatten()
        .chain(p.velocity.iter().flatten())
    {
        hash = (hash ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3);
    }
    println!(
        "particle_steps_per_s={:.6e} threads={threads} seconds={elapsed:.4} particles={n} rebuilds={} state_hash={hash:016x}",
        n as f64 * steps as f64 / elapsed,
        sim.neighbors().build_count - builds0
    );
}
