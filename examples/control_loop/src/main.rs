//! Runs the two 1 kHz computed-torque loops, with an `f32` and with an `f64` controller side by
//! side, for a few seconds of simulated time against the runtime's plant, and prints the
//! tracking errors next to the zero-order-hold estimate, how far the two loops drift apart next
//! to the `f32` rounding floor (see the library docs), the `f32`-vs-`f64` torque agreement, and
//! the time of one control tick.
//!
//! `cargo run --release -p control-loop -- [seconds] [natural frequency, Hz]`

use control_loop::bench::{self, Rounding};
use control_loop::{Gains, Stats, Timing, cast, gough_stewart, norm_inf, puma};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Time per call of `f`: the best of 7 batches of `reps` calls (the machine may be shared).
fn time(reps: u32, mut f: impl FnMut(u32)) -> Duration {
    (0..7)
        .map(|_| {
            let start = Instant::now();
            for k in 0..reps {
                f(k);
            }
            start.elapsed() / reps
        })
        .min()
        .expect("7 batches")
}

fn puma_tick<S: puma::Scalar>(reference: puma::Reference<f64>, gains: Gains<f64>) -> Duration {
    let c = puma::Controller::<S> {
        gains: Gains {
            kp: S::from_f64(gains.kp),
            kd: S::from_f64(gains.kd),
        },
        reference: reference.cast(),
    };
    let (q, qd, _) = c.reference.at(S::from_f64(0.5));
    time(10_000, |k| {
        black_box(c.step(black_box(S::from_f64(k as f64 * 1e-4)), &q, &qd));
    })
}

fn gough_stewart_tick<S: gough_stewart::Scalar>(
    reference: gough_stewart::Reference<f64>,
    gains: Gains<f64>,
) -> Duration {
    let g = Gains {
        kp: S::from_f64(gains.kp),
        kd: S::from_f64(gains.kd),
    };
    let mut c = gough_stewart::Controller::<S>::new(g, reference.cast());
    let (x, u, _) = reference.at(0.5);
    c.estimate = cast(&x);
    let lengths = mechanisms::gough_stewart::inverse_kinematics(&x).expect("pose in reach");
    let (q, u): ([S; 6], [S; 6]) = (cast(&lengths), cast(&u));
    time(10_000, |k| {
        let t = black_box(S::from_f64(0.5 + k as f64 * 1e-7));
        black_box(c.step(t, &q, &u).expect("tick"));
    })
}

fn rounding(what: &str, r: &Rounding, kp: f64, unit: &str) {
    println!(
        "  {what}: f32 vs f64 torque along the reference: max |δτ| {:.2e} (relative {:.2e}); rounding floor max|M⁻¹δτ|/kp = {:.2e} {unit}",
        r.torque_absolute,
        r.torque_relative,
        r.acceleration / kp
    );
}

fn main() {
    let mut args = std::env::args().skip(1);
    let seconds: f64 = args.next().map_or(5.0, |s| s.parse().expect("seconds"));
    let hz: f64 = args
        .next()
        .map_or(8.0, |s| s.parse().expect("natural frequency (Hz)"));
    let gains = Gains::<f64>::critically_damped(hz);
    let timing = Timing::KHZ;
    println!(
        "computed torque at {} Hz, plant (runtime, f64) RK4 at {} Hz, kp = {:.1} 1/s², kd = {:.2} 1/s ({hz} Hz, critically damped), {seconds} s",
        1.0 / timing.period,
        timing.substeps as f64 / timing.period,
        gains.kp,
        gains.kd
    );

    let ticks = (seconds / timing.period) as u32;
    let r = puma::Reference::DEMO;
    let p = bench::puma::predicted_max_error(gains, &r, timing, seconds).expect("prediction");
    let f = bench::puma::rounding_floor(gains, &r, timing, seconds).expect("rounding");
    let (mut l32, mut l64) = (
        bench::puma::Loop::<f32>::new(gains, r, timing),
        bench::puma::Loop::<f64>::new(gains, r, timing),
    );
    let (mut s32, mut s64, mut drift) = (Stats::default(), Stats::default(), Stats::default());
    for _ in 0..ticks {
        let (e32, e64) = (l32.tick().expect("f32 loop"), l64.tick().expect("f64 loop"));
        s32.add(norm_inf(&e32));
        s64.add(norm_inf(&e64));
        drift.add(norm_inf(&core::array::from_fn::<f64, 6, _>(|i| {
            e32[i] - e64[i]
        })));
    }
    println!("puma560 joint error ‖q_d − q‖∞ (rad), {ticks} ticks; hold estimate max {p:.3e}");
    for (name, s) in [("f32", s32), ("f64", s64)] {
        println!(
            "  {name} controller: max {:.3e}  rms {:.3e}",
            s.max,
            s.rms()
        );
    }
    rounding("puma560", &f, gains.kp, "rad");
    println!(
        "  f32 loop − f64 loop: max {:.3e} rad (bound: the rounding floor)",
        drift.max
    );

    let r = gough_stewart::Reference::DEMO;
    let (pr, pt) =
        bench::gough_stewart::predicted_max_error(gains, &r, timing, seconds).expect("prediction");
    let (fr, ft) =
        bench::gough_stewart::rounding_floor(gains, &r, timing, seconds).expect("rounding");
    let (mut l32, mut l64) = (
        bench::gough_stewart::Loop::<f32>::new(gains, r, timing),
        bench::gough_stewart::Loop::<f64>::new(gains, r, timing),
    );
    let (mut t32, mut t64, mut drift) = (
        bench::gough_stewart::Tracking::default(),
        bench::gough_stewart::Tracking::default(),
        bench::gough_stewart::Tracking::default(),
    );
    for _ in 0..ticks {
        let (e32, e64) = (l32.tick().expect("f32 loop"), l64.tick().expect("f64 loop"));
        t32.add(&e32);
        t64.add(&e64);
        drift.add(&core::array::from_fn(|i| e32[i] - e64[i]));
    }
    println!(
        "gough_stewart pose error ‖δθ‖∞ (rad), ‖δp‖∞ (m), {ticks} ticks; hold estimate max {pr:.3e} rad, {pt:.3e} m"
    );
    for (name, t) in [("f32", t32), ("f64", t64)] {
        println!(
            "  {name} controller: rotation max {:.3e} rms {:.3e} rad; translation max {:.3e} rms {:.3e} m",
            t.rotation.max,
            t.rotation.rms(),
            t.translation.max,
            t.translation.rms()
        );
    }
    rounding("gough_stewart rotation", &fr, gains.kp, "rad");
    rounding("gough_stewart translation", &ft, gains.kp, "m");
    println!(
        "  f32 pose estimate (forward kinematics) along the reference: max error {:.2e} rad, {:.2e} m",
        fr.estimate, ft.estimate
    );
    println!(
        "  f32 loop − f64 loop: max {:.3e} rad, {:.3e} m (bound: the rounding floors)",
        drift.rotation.max, drift.translation.max
    );

    println!(
        "control tick alone (this host, best of 7 batches): puma560 f32 {:.2?}, f64 {:.2?}; gough_stewart f32 {:.2?}, f64 {:.2?} (of a 1 ms period)",
        puma_tick::<f32>(puma::Reference::DEMO, gains),
        puma_tick::<f64>(puma::Reference::DEMO, gains),
        gough_stewart_tick::<f32>(r, gains),
        gough_stewart_tick::<f64>(r, gains),
    );
}
