//! Runs the two 1 kHz computed-torque loops for a few seconds of simulated time and prints the
//! tracking errors next to the zero-order-hold prediction (see the library docs).
//!
//! `cargo run --release -p control-loop -- [seconds] [natural frequency, Hz]`

use control_loop::{F, Gains, Timing, gough_stewart, puma};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let seconds: F = args.next().map_or(5.0, |s| s.parse().expect("seconds"));
    let hz: F = args
        .next()
        .map_or(8.0, |s| s.parse().expect("natural frequency (Hz)"));
    let gains = Gains::critically_damped(hz);
    let timing = Timing::KHZ;
    println!(
        "computed torque at {} Hz, plant RK4 at {} Hz, kp = {:.1} 1/s², kd = {:.2} 1/s ({hz} Hz, critically damped), {seconds} s",
        1.0 / timing.period,
        timing.substeps as F / timing.period,
        gains.kp,
        gains.kd
    );

    let c = puma::Controller {
        gains,
        reference: puma::Reference::DEMO,
    };
    let start = Instant::now();
    let s = puma::run(&c, timing, seconds).expect("PUMA 560 loop");
    let wall = start.elapsed();
    let p = puma::predicted_max_error(&c, timing, seconds).expect("prediction");
    println!(
        "puma560       joint error  max {:.3e} rad  rms {:.3e} rad  (predicted max {:.3e} rad)  {} ticks in {:.0?}",
        s.max,
        s.rms(),
        p,
        s.count(),
        wall
    );

    let r = gough_stewart::Reference::DEMO;
    // The firmware part alone: one control tick (pose by forward kinematics for the platform).
    let reps = 20_000;
    let (q, qd, _) = c.reference.at(0.5);
    let start = Instant::now();
    for k in 0..reps {
        std::hint::black_box(c.step(std::hint::black_box(k as F * 1e-4), &q, &qd));
    }
    let puma_tick = start.elapsed() / reps;
    let mut gc = gough_stewart::Controller::new(gains, r);
    let (x, u, _) = r.at(0.5);
    let lengths = mechanisms::gough_stewart::inverse_kinematics(&x).expect("pose in reach");
    let start = Instant::now();
    for k in 0..reps {
        let t = std::hint::black_box(0.5 + k as F * 1e-7);
        std::hint::black_box(gc.step(t, &lengths, &u).expect("tick"));
    }
    let gs_tick = start.elapsed() / reps;
    println!(
        "control tick alone: puma560 {puma_tick:.2?}, gough_stewart {gs_tick:.2?} (of a 1 ms period)"
    );

    let start = Instant::now();
    let t = gough_stewart::run(gains, &r, timing, seconds).expect("Gough–Stewart loop");
    let wall = start.elapsed();
    let (pr, pt) =
        gough_stewart::predicted_max_error(gains, &r, timing, seconds).expect("prediction");
    println!(
        "gough_stewart rotation     max {:.3e} rad  rms {:.3e} rad  (predicted max {:.3e} rad)",
        t.rotation.max,
        t.rotation.rms(),
        pr
    );
    println!(
        "gough_stewart translation  max {:.3e} m    rms {:.3e} m    (predicted max {:.3e} m)  {} ticks in {:.0?}",
        t.translation.max,
        t.translation.rms(),
        pt,
        t.translation.count(),
        wall
    );
}
