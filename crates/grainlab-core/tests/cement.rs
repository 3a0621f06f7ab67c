//! Cement bonds (parallel and contact bonds that break): the closed forms of
//! a bonded pair pulled, sheared under a held normal stress and bent, a
//! cantilever against Euler-Bernoulli, the energy ledger through a break, the
//! same bits on 1 to 4 threads and after a resume while bonds are breaking,
//! and permanent bonds that never break.
mod common;
use common::*;
use grainlab_core::cement::{BreakMode, CementKind, CementSpec};
use grainlab_core::state::{FIX_ROTATION, FIX_X, FIX_Y};
use grainlab_core::{ContactModel, Simulation};

const R: f64 = 1.0e-3;
/// `kn_bar` such that a bond of `lambda_b = 1` between two disks of radius
/// `R` has the contact law's `k_n`: `kn_bar A = KN`.
const KN_BAR: f64 = KN / (2.0 * R);
const ALL: u8 = FIX_X | FIX_Y | FIX_ROTATION;

fn parallel(sigma_c: f64, c: f64, phi: f64) -> CementSpec {
    CementSpec {
        kind: CementKind::Parallel,
        radius_multiplier: 1.0,
        normal_stiffness: KN_BAR,
        shear_stiffness: KN_BAR,
        tensile_strength: sigma_c,
        cohesion: c,
        friction_angle: phi,
    }
}

/// Two disks of radius `R` at centre distance `2R + gap` on the x axis,
/// cemented by `spec`, both held (`fixity`), dt = 0.1 sqrt(m / kn).
fn held_pair(gap: f64, spec: CementSpec) -> Simulation {
    let mut sim = disks(
        vec![[0.0, 0.0], [2.0 * R + gap, 0.0]],
        vec![R, R],
        ContactModel::linear(KN, KN, 0.5),
        1.0,
    );
    let m = sim.particles().mass[0];
    let mut params = sim.params();
    params.time_step = 0.1 * (m / KN).sqrt();
    sim.set_params(params).unwrap();
    sim.set_fixity(&[ALL, ALL]).unwrap();
    sim.add_cement_bonds(&[(0, 1)], &[spec]).unwrap();
    sim
}

/// Runs one step at a time until the bond breaks (at most `limit` steps);
/// returns the break.
fn run_to_break(sim: &mut Simulation, limit: u64) -> grainlab_core::cement::BondBreak {
    for _ in 0..limit {
        sim.run(1).unwrap();
        if sim.cement().bonds.is_empty() {
            let breaks = sim.take_bond_breaks();
            assert_eq!(breaks.len(), 1);
            return breaks[0];
        }
    }
    panic!("no break in {limit} steps");
}

#[test]
fn a_pair_pulled_apart_breaks_at_sigma_c_times_a() {
    let sigma_c = 1.0e6;
    let mut sim = held_pair(0.0, parallel(sigma_c, 1.0e9, 0.0));
    let b = sim.cement().bonds[0];
    let (kn, area, dt) = (b.normal_stiffness, b.area, sim.params().time_step);
    let v = 1.0e-4;
    sim.set_velocities(&[[0.0, 0.0], [v, 0.0]]).unwrap();
    // the evaluation at step n sees the distance 2R + n v dt: tension kn n v dt
    let limit = sigma_c * area;
    let expected = (limit / (kn * v * dt)).ceil() as u64;
    let fraction = limit / (kn * v * dt) - (expected as f64 - 1.0);
    assert!(fraction > 0.01 && fraction < 0.99, "not at a rounding edge");
    let brk = run_to_break(&mut sim, 5 * expected);
    assert_eq!(brk.mode, BreakMode::Tension);
    assert_eq!(brk.step, expected, "the step of the break");
    let tension = -brk.normal_force;
    assert!(
        tension >= limit && tension - kn * v * dt < limit,
        "{tension} vs {limit}"
    );
    assert!((tension / (kn * v * dt * expected as f64) - 1.0).abs() < 1e-9);
    assert!((brk.energy - 0.5 * tension * tension / kn).abs() <= 1e-12 * brk.energy);
    assert_eq!((brk.i, brk.j), (0, 1));
    assert_eq!(brk.normal, [1.0, 0.0]);
    let d = 2.0 * R + expected as f64 * v * dt;
    assert!((brk.position[0] - 0.5 * d).abs() < 1e-15 && brk.position[1] == 0.0);
    assert!((brk.time - expected as f64 * dt).abs() < 1e-12 * brk.time);
    // the ledger books half a step of the bond's work besides (leapfrog's share)
    let half_step_work = 0.5 * dt * (-tension) * v;
    let booked = sim.energy().bond_released;
    assert!((booked - (brk.energy + half_step_work)).abs() < 1e-12 * brk.energy);
}

/// The step at which a pair whose normal force is held at `held` (N,
/// compression positive) and sheared by spinning both disks breaks, with the
/// step predicted from `tau_c = c - sigma tan(phi_b)`.
fn shear_break_step(held: f64) -> (u64, u64) {
    let (sigma_c, c, phi) = (1.0e6, 2.0e6, 30.0);
    let gap = 0.1 * R;
    let mut sim = held_pair(gap, parallel(sigma_c, c, phi));
    let b = sim.cement().bonds[0];
    let (kn, ks, area, dt) = (
        b.normal_stiffness,
        b.shear_stiffness,
        b.area,
        sim.params().time_step,
    );
    // hold the normal force: a jump of the positions (no shear), kept by fixity
    let d = 2.0 * R + gap - held / kn;
    sim.set_positions(&[[0.0, 0.0], [d, 0.0]]).unwrap();
    // both disks spinning alike: v_t = -omega d at the contact, no relative rotation
    let omega = 0.02;
    sim.set_angular_velocities(&[omega, omega]).unwrap();
    let fn_ = kn * (2.0 * R + gap - d);
    let sigma = -fn_ / area;
    let strength = c - sigma * phi.to_radians().tan();
    // the first evaluation after the spins were set adds no increment
    let per_step = ks * omega * d * dt / area;
    let expected = (strength / per_step).ceil() as u64;
    let fraction = strength / per_step - (expected as f64 - 1.0);
    assert!(fraction > 0.01 && fraction < 0.99, "not at a rounding edge");
    let brk = run_to_break(&mut sim, 5 * expected);
    assert_eq!(brk.mode, BreakMode::Shear);
    assert!(brk.moment == 0.0, "no relative rotation, no moment");
    let tau = brk.shear_force.abs() / area;
    assert!(tau >= strength && tau - per_step < strength);
    (brk.step, expected)
}

#[test]
fn a_sheared_pair_breaks_at_c_minus_sigma_tan_phi() {
    // compression (1 MPa on the bond), none, tension (0.5 MPa, below sigma_c)
    let area = 2.0 * R;
    let steps: Vec<u64> = [1.0e6 * area, 0.0, -0.5e6 * area]
        .into_iter()
        .map(|held| {
            let (step, expected) = shear_break_step(held);
            assert_eq!(step, expected, "held normal force {held} N");
            step
        })
        .collect();
    // compression strengthens, tension weakens
    assert!(steps[0] > steps[1] && steps[1] > steps[2], "{steps:?}");
}

#[test]
fn a_relative_rotation_bends_the_bond_until_sigma_max_reaches_sigma_c() {
    let sigma_c = 1.0e6;
    let mut sim = held_pair(0.0, parallel(sigma_c, 1.0e9, 0.0));
    let b = sim.cement().bonds[0];
    let (kn_bar, rb, dt) = (KN_BAR, b.bond_radius, sim.params().time_step);
    let inertia = 2.0 / 3.0 * rb.powi(3);
    // opposite spins: no shear at the contact point, relative rotation 2 omega dt a step
    let omega = 0.05;
    sim.set_angular_velocities(&[-omega, omega]).unwrap();
    sim.run(101).unwrap();
    let dtheta = 2.0 * omega * dt * 100.0;
    let m = sim.cement().bonds[0].moment;
    assert!(
        (m + kn_bar * inertia * dtheta).abs() < 1e-12 * m.abs(),
        "M = {m}"
    );
    assert_eq!(sim.cement().bonds[0].shear, 0.0);
    // breaks in tension at |M| R_b / I = sigma_c: dtheta_c = sigma_c / (kn_bar R_b)
    let theta_c = sigma_c / (kn_bar * rb);
    let expected = (theta_c / (2.0 * omega * dt)).ceil() as u64;
    let brk = run_to_break(&mut sim, 5 * expected);
    assert_eq!(brk.mode, BreakMode::Tension);
    assert_eq!(brk.step, expected);
    let sigma_max = brk.moment.abs() * rb / inertia;
    assert!(sigma_max >= sigma_c && sigma_max < sigma_c * (1.0 + 1.0 / expected as f64));
}

/// The cantilever: `n + 1` disks in a row at spacing `L_b = 2R + gap`, the
/// first held, a transverse load `p` on the last, local damping to rest.
fn cantilever(n: usize, ks_bar: f64, p: f64) -> (f64, f64) {
    let gap = 1.0e-3 * R;
    let lb = 2.0 * R + gap;
    let pos: Vec<[f64; 2]> = (0..=n).map(|k| [k as f64 * lb, 0.0]).collect();
    let mut sim = disks(pos, vec![R; n + 1], ContactModel::linear(KN, KN, 0.5), 1.0);
    let mut spec = parallel(1.0e12, 1.0e12, 0.0);
    spec.shear_stiffness = ks_bar;
    let pairs: Vec<(usize, usize)> = (0..n).map(|k| (k, k + 1)).collect();
    sim.add_cement_bonds(&pairs, &[spec]).unwrap();
    let mut fixity = vec![0u8; n + 1];
    fixity[0] = ALL;
    sim.set_fixity(&fixity).unwrap();
    let mut params = sim.params();
    params.time_step = sim.critical_time_step(0.2).unwrap();
    params.local_damping = 0.7;
    sim.set_params(params).unwrap();
    let mut load = vec![[0.0, 0.0]; n + 1];
    load[n] = [0.0, -p];
    sim.set_external_forces(&load).unwrap();
    let mut last = 0.0;
    for _ in 0..400 {
        sim.run(1000).unwrap();
        let w = -sim.particles().position[sim.internal_index(n)][1];
        if (w - last).abs() < 1e-9 * w {
            break;
        }
        last = w;
    }
    let w = -sim.particles().position[sim.internal_index(n)][1];
    assert!(sim.cement().bonds.len() == n, "no bond broke");
    (w, lb)
}

#[test]
fn a_cantilever_of_bonded_disks_deflects_as_an_euler_bernoulli_beam() {
    // Each bond is a beam segment of length L_b: M = kn_bar I dtheta and the
    // curvature dtheta / L_b give EI = kn_bar I L_b. The chain's nodes have the
    // continuous beam's slopes (the moment is linear along the bond), and the
    // deflection sums the trapezoids of the slopes, P L h^2 / (12 EI) below
    // P L^3 / (3 EI), plus the bonds' shear springs (Timoshenko's shear
    // deflection, n P / (ks_bar A)): both 1 / (4 n^2) of the whole at
    // ks_bar = kn_bar, 0.25 % each with 10 bonds. The test compares with the
    // Euler-Bernoulli beam to 2 % and with the discrete sum to 0.1 %.
    let (n, p) = (10, 0.05);
    let (w, lb) = cantilever(n, KN_BAR, p);
    let rb = R;
    let (area, inertia) = (2.0 * rb, 2.0 / 3.0 * rb.powi(3));
    let ei = KN_BAR * inertia * lb;
    let l = n as f64 * lb;
    let euler_bernoulli = p * l.powi(3) / (3.0 * ei);
    let discrete = euler_bernoulli - p * l * lb * lb / (12.0 * ei) + n as f64 * p / (KN_BAR * area);
    eprintln!("w = {w:e}, EB {euler_bernoulli:e}, discrete {discrete:e}");
    assert!(
        (w / euler_bernoulli - 1.0).abs() < 0.02,
        "{w} vs {euler_bernoulli}"
    );
    assert!((w / discrete - 1.0).abs() < 1e-3, "{w} vs {discrete}");
    // a ten times stiffer shear spring takes most of the shear term away
    let (w_stiff, _) = cantilever(n, 10.0 * KN_BAR, p);
    let discrete_stiff = discrete - 0.9 * n as f64 * p / (KN_BAR * area);
    assert!(
        (w_stiff / discrete_stiff - 1.0).abs() < 1e-3,
        "{w_stiff} vs {discrete_stiff}"
    );
}

/// Four disks in a row (gaps of 0.1 R), the first held, the last launched
/// away from the others at 0.012 m/s and spinning at `spin`, 3,000 steps
/// without damping or contact: returns the initial balance, its largest
/// drift, its change over the steps where bonds broke, its largest change
/// over one other step, and the breaks.
fn launched_chain(spin: f64) -> (f64, f64, f64, f64, Vec<grainlab_core::cement::BondBreak>) {
    let n = 4;
    let pos: Vec<[f64; 2]> = (0..n).map(|k| [2.1 * R * k as f64, 0.0]).collect();
    let mut sim = disks(pos, vec![R; n], ContactModel::linear(KN, KN, 0.5), 1.0);
    let specs: Vec<CementSpec> = [1.0e6, 1.2e6, 1.3e6]
        .iter()
        .map(|&s| parallel(s, 1.0e6, 0.0))
        .collect();
    sim.add_cement_bonds(&[(0, 1), (1, 2), (2, 3)], &specs)
        .unwrap();
    let mut fixity = vec![0u8; n];
    fixity[0] = ALL;
    sim.set_fixity(&fixity).unwrap();
    let mut params = sim.params();
    params.time_step = sim.critical_time_step(0.1).unwrap();
    sim.set_params(params).unwrap();
    let mut velocity = vec![[0.0, 0.0]; n];
    velocity[n - 1] = [0.012, 0.0];
    sim.set_velocities(&velocity).unwrap();
    let mut spins = vec![0.0; n];
    spins[n - 1] = spin;
    sim.set_angular_velocities(&spins).unwrap();
    sim.run(1).unwrap();
    let b0 = sim.energy().balance();
    let (mut worst, mut at_breaks, mut other, mut last) = (0.0f64, 0.0f64, 0.0f64, b0);
    for _ in 0..3000 {
        let intact = sim.cement().bonds.len();
        sim.run(1).unwrap();
        let b = sim.energy().balance();
        if sim.cement().bonds.len() < intact {
            at_breaks = at_breaks.max((b - last).abs());
        } else {
            other = other.max((b - last).abs());
        }
        worst = worst.max((b - b0).abs());
        last = b;
        assert_eq!(sim.measurements().contact_count, 0, "no contact onset");
    }
    let e = sim.energy();
    let breaks = sim.take_bond_breaks();
    let stored: f64 = breaks.iter().map(|b| b.energy).sum();
    assert!(e.bond_released > 0.1 * b0, "{e:?}");
    // the booked half step of work is a small share of the stored energy
    assert!(
        (e.bond_released / stored - 1.0).abs() < 0.05,
        "{e:?} {stored}"
    );
    (b0, worst, at_breaks, other, breaks)
}

#[test]
fn the_ledger_balances_through_a_break() {
    // Leapfrog conserves 1/2 m v(n-1/2).v(n+1/2) plus the springs' energy
    // exactly while the springs stay linear in the motion: pulled along the
    // row, kinetic + elastic + released stays constant to round-off only if
    // each break books its bond's energy (and the half step of work its force
    // no longer does) on the released line; without that half step the drift
    // is 1.6 % of the energy.
    let (b0, worst, _, _, breaks) = launched_chain(0.0);
    assert!(!breaks.is_empty(), "no break");
    eprintln!(
        "{} breaks; drift {:.3e} of the energy",
        breaks.len(),
        worst / b0
    );
    assert!(worst < 1e-11 * b0, "drift {:.3e} of the energy", worst / b0);
    // With the last disk spinning the bonds shear and bend as the chain turns
    // (not linear in the motion: leapfrog's drift, 1e-5 of the energy), and a
    // step with a break changes the balance no more than the others.
    let (b0, worst, at_breaks, other, breaks) = launched_chain(2.0);
    assert!(
        !breaks.is_empty()
            && breaks
                .iter()
                .all(|b| b.shear_force != 0.0 && b.moment != 0.0)
    );
    eprintln!(
        "spinning: drift {:.3e}, at breaks {:.3e}, other steps {:.3e} of the energy",
        worst / b0,
        at_breaks / b0,
        other / b0
    );
    assert!(
        worst < 1e-4 * b0 && at_breaks <= other,
        "{worst} {at_breaks} {other}"
    );
}

/// A 3,600-disk box (the team's parallel path) with every touching pair
/// cemented (strengths scattered by a seeded generator) and squeezed by its
/// top wall: bonds break from the first hundreds of steps.
fn cemented_box(threads: usize) -> Simulation {
    let n_side = 60;
    let mut sim = boxed_packing(n_side, 0.5, 7, threads);
    let contacts = sim.contacts().unwrap();
    let pairs: Vec<(usize, usize)> = (0..contacts.i.len())
        .filter(|&k| !contacts.bonded[k])
        .map(|k| (contacts.i[k] as usize, contacts.j[k] as usize))
        .collect();
    let mut rng = Rng::new(3);
    let specs: Vec<CementSpec> = pairs
        .iter()
        .map(|_| {
            let mut s = parallel(rng.uniform(0.5e6, 4.0e6), rng.uniform(1.0e6, 8.0e6), 20.0);
            s.radius_multiplier = 0.8;
            s
        })
        .collect();
    sim.add_cement_bonds(&pairs, &specs).unwrap();
    sim.set_wall_velocity(2, [0.005, -0.005]).unwrap();
    sim
}

/// Particles, springs (contacts, cement), the break log and the ledger, as bits.
fn cement_fingerprint(sim: &mut Simulation) -> Vec<u64> {
    let mut bits = contact_list_bits(sim);
    let p = sim.particles();
    for (x, v) in sim
        .to_external(&p.position)
        .iter()
        .zip(sim.to_external(&p.velocity))
    {
        bits.extend([x[0], x[1], v[0], v[1]].map(f64::to_bits));
    }
    for b in &sim.cement().bonds {
        bits.extend([sim.external_index(b.i as usize) as u64]);
        bits.extend([b.shear, b.moment].map(f64::to_bits));
    }
    for b in &sim.cement().breaks {
        bits.extend([b.step, b.i as u64, b.j as u64, b.mode as u64]);
        bits.extend([b.energy, b.position[0], b.normal[1], b.moment].map(f64::to_bits));
    }
    let e = sim.energy();
    bits.extend([e.kinetic, e.elastic, e.bond_released, e.balance()].map(f64::to_bits));
    bits
}

#[test]
fn breaks_give_the_same_bits_on_one_to_four_threads() {
    let mut reference: Option<(Vec<u64>, usize)> = None;
    for threads in [1, 2, 3, 4] {
        let mut sim = cemented_box(threads);
        let intact = sim.cement().bonds.len();
        sim.run(600).unwrap();
        assert!(sim.neighbors().stripe_ranges.len() > 1, "the parallel path");
        let broken = sim.cement().breaks.len();
        assert!(broken > 20 && broken < intact, "{broken} of {intact} broke");
        assert_eq!(sim.cement().bonds.len() + broken, intact);
        assert_eq!(sim.bonds().len(), 59, "the membrane's bonds never break");
        let now = (cement_fingerprint(&mut sim), broken);
        match &reference {
            None => reference = Some(now),
            Some(r) => assert!(*r == now, "{threads} threads differ from one"),
        }
    }
}

#[test]
fn a_run_resumed_from_a_checkpoint_taken_while_bonds_break_is_the_same() {
    let mut straight = cemented_box(2);
    straight.run(300).unwrap();
    let breaks_at_checkpoint = straight.cement().breaks.len();
    assert!(
        breaks_at_checkpoint > 0,
        "bonds are breaking at the checkpoint"
    );
    let bytes = straight.to_bytes().unwrap();
    straight.run(300).unwrap();
    let mut resumed = Simulation::from_bytes(&bytes).unwrap();
    resumed.set_threads(3).unwrap();
    resumed.run(300).unwrap();
    assert!(straight.cement().breaks.len() > breaks_at_checkpoint + 10);
    assert_eq!(
        cement_fingerprint(&mut resumed),
        cement_fingerprint(&mut straight)
    );
}

#[test]
fn a_permanent_bond_never_breaks_and_a_cement_bond_beside_it_does() {
    // Pair 0-1 has a permanent bond, pair 2-3 cement of a small strength, both
    // pulled apart far beyond it.
    let pos = vec![
        [0.0, 0.0],
        [2.0 * R, 0.0],
        [0.0, 5.0 * R],
        [2.0 * R, 5.0 * R],
    ];
    let mut sim = disks(pos, vec![R; 4], ContactModel::linear(KN, KN, 0.5), 1.0);
    let mut params = sim.params();
    params.time_step = 0.1 * (sim.particles().mass[0] / KN).sqrt();
    sim.set_params(params).unwrap();
    sim.add_bond(0, 1, KN, KN, None).unwrap();
    sim.add_cement_bonds(&[(2, 3)], &[parallel(1.0e4, 1.0e4, 0.0)])
        .unwrap();
    sim.set_fixity(&[ALL; 4]).unwrap();
    sim.set_velocities(&[[0.0, 0.0], [1.0e-3, 0.0], [0.0, 0.0], [1.0e-3, 0.0]])
        .unwrap();
    sim.run(2000).unwrap();
    assert_eq!(sim.bonds().len(), 1);
    assert!(sim.cement().bonds.is_empty());
    let c = sim.contacts().unwrap();
    assert_eq!(c.i.len(), 1, "the permanent bond is listed, still carrying");
    assert!(c.bonded[0] && c.normal_force[0] < -0.5 * KN * 2000.0 * 1.0e-3 * params.time_step);
}

#[test]
fn a_cemented_pair_also_feels_the_contact_law_and_after_the_break_only_it() {
    // Bonded overlapping by delta0, squeezed by delta1 more: the contact law
    // pushes with KN (delta0 + delta1), the bond with kn_bar A delta1 (its rest
    // length is the bonding distance). Spun until it breaks in shear, the
    // contact law alone remains.
    let (delta0, delta1) = (1.0e-5, 2.0e-6);
    let mut sim = held_pair(-delta0, parallel(1.0e9, 1.0e5, 0.0));
    let kn_bond = sim.cement().bonds[0].normal_stiffness;
    sim.set_positions(&[[0.0, 0.0], [2.0 * R - delta0 - delta1, 0.0]])
        .unwrap();
    sim.run(1).unwrap();
    let force_on_1 = |sim: &Simulation| sim.particles().force[sim.internal_index(1)][0];
    let expected = KN * (delta0 + delta1) + kn_bond * delta1;
    assert!((force_on_1(&sim) / expected - 1.0).abs() < 1e-9);
    sim.set_angular_velocities(&[0.5, 0.5]).unwrap();
    let brk = run_to_break(&mut sim, 100_000);
    assert_eq!(brk.mode, BreakMode::Shear);
    sim.set_angular_velocities(&[0.0, 0.0]).unwrap();
    sim.run(1).unwrap();
    let alone = force_on_1(&sim);
    assert!(
        (alone / (KN * (delta0 + delta1)) - 1.0).abs() < 1e-9,
        "{alone}"
    );
}

#[test]
fn bad_cement_is_refused_before_any_bond_is_made() {
    let mut sim = held_pair(0.0, parallel(1.0e6, 1.0e6, 0.0));
    sim.add_particles(vec![[5.0 * R, 0.0]], vec![R], vec![DENSITY])
        .unwrap();
    let ok = parallel(1.0e6, 1.0e6, 0.0);
    let refusal = |sim: &mut Simulation, pairs: &[(usize, usize)], spec: CementSpec| {
        sim.add_cement_bonds(pairs, &[spec])
            .unwrap_err()
            .to_string()
    };
    let mut negative = ok;
    negative.cohesion = -1.0;
    for (pairs, spec, start) in [
        (
            vec![(1, 2), (2, 2)],
            ok,
            "cement[1]: cannot cement particle 2 to itself",
        ),
        (
            vec![(1, 2), (0, 3)],
            ok,
            "cement.j[1]: particle index 3 out of range",
        ),
        (
            vec![(1, 2), (2, 1)],
            ok,
            "cement[1]: particles 2 and 1 are already cemented",
        ),
        (
            vec![(1, 0)],
            ok,
            "cement[0]: particles 1 and 0 are already cemented",
        ),
        (
            vec![(1, 2)],
            negative,
            "cement.cohesion[0]: must be finite and >= 0",
        ),
    ] {
        let e = refusal(&mut sim, &pairs, spec);
        assert!(e.starts_with(start), "{e}");
        assert_eq!(sim.cement().bonds.len(), 1, "nothing made");
    }
    let mut lambda = ok;
    lambda.radius_multiplier = 0.0;
    assert!(refusal(&mut sim, &[(1, 2)], lambda).starts_with("cement.radius_multiplier[0]"));
}
