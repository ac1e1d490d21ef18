//! The 1 kHz loops, with `f32` and with `f64` controllers against the runtime's `f64` plant,
//! track their references as the crate docs derive:
//!
//! * the `f64` loop's largest error lies within a factor of 1.5 of the zero-order-hold estimate
//!   `(h/2) · max ‖∂FD/∂τ · τ̇_d‖∞ / kp`, and it grows in proportion to the control period;
//! * the `f32` loop stays, at every tick, within `sup ‖M⁻¹ δτ‖∞ / kp` of the `f64` loop, where
//!   `δτ` is the `f32` controller's torque error measured open-loop along the reference (the
//!   bound of a critically damped loop driven by a bounded acceleration error);
//! * the `f32` control step allocates nothing.

use control_loop::bench::{self, Rounding};
use control_loop::{Gains, Stats, Timing, cast, gough_stewart, norm_inf, puma};

/// Simulated seconds per run (the references' slowest period is 5 s; 2 s covers every joint's
/// fastest excursion).
const SECONDS: f64 = 2.0;

fn gains() -> Gains<f64> {
    Gains::critically_damped(8.0)
}

fn as_predicted(what: &str, measured: f64, predicted: f64) {
    println!("{what}: max error {measured:.3e}, predicted {predicted:.3e}");
    assert!(
        predicted > 0.0 && predicted.is_finite(),
        "{what}: prediction {predicted}"
    );
    assert!(
        measured <= 1.5 * predicted && measured >= predicted / 1.5,
        "{what}: max error {measured:e} vs predicted {predicted:e}"
    );
}

/// `max ‖e₃₂ − e₆₄‖∞` over the ticks within the rounding floor, and the `f32` loop's largest
/// error within the hold estimate widened by that floor.
fn within_floor(what: &str, drift: f64, floor: f64, f32_max: f64, predicted: f64) {
    println!(
        "{what}: f32 loop − f64 loop max {drift:.3e}, floor {floor:.3e}; f32 max error {f32_max:.3e}"
    );
    assert!(floor > 0.0 && floor.is_finite(), "{what}: floor {floor}");
    assert!(drift <= floor, "{what}: {drift:e} > floor {floor:e}");
    assert!(
        f32_max <= 1.5 * predicted + floor && f32_max >= predicted / 1.5 - floor,
        "{what}: f32 max error {f32_max:e} vs predicted {predicted:e} ± {floor:e}"
    );
}

/// The torque figures are f32-sized: above the unit roundoff (the controller is not secretly
/// `f64`) and far below 1 (it is not broken).
fn torque_is_single_precision(what: &str, r: &Rounding) {
    println!(
        "{what}: f32 vs f64 torque max {:.2e} (relative {:.2e})",
        r.torque_absolute, r.torque_relative
    );
    assert!(
        r.torque_relative > f32::EPSILON as f64 / 2.0 && r.torque_relative < 1e-2,
        "{what}: {}",
        r.torque_relative
    );
}

#[test]
fn puma_f32_and_f64_loops() {
    let r = puma::Reference::DEMO;
    let (mut l32, mut l64) = (
        bench::puma::Loop::<f32>::new(gains(), r, Timing::KHZ),
        bench::puma::Loop::<f64>::new(gains(), r, Timing::KHZ),
    );
    let (mut s32, mut s64, mut drift) = (Stats::default(), Stats::default(), Stats::default());
    for _ in 0..(SECONDS / Timing::KHZ.period) as u32 {
        let (e32, e64) = (l32.tick().expect("f32 loop"), l64.tick().expect("f64 loop"));
        s32.add(norm_inf(&e32));
        s64.add(norm_inf(&e64));
        drift.add(norm_inf(&core::array::from_fn::<f64, 6, _>(|i| {
            e32[i] - e64[i]
        })));
    }
    let p = bench::puma::predicted_max_error(gains(), &r, Timing::KHZ, SECONDS).expect("estimate");
    as_predicted("puma560 f64", s64.max, p);
    assert!(s64.rms() <= s64.max);
    // Small: a thousandth of the smallest amplitude.
    assert!(s64.max < 1e-3 * 0.3, "{}", s64.max);
    let f = bench::puma::rounding_floor(gains(), &r, Timing::KHZ, SECONDS).expect("floor");
    torque_is_single_precision("puma560", &f);
    within_floor(
        "puma560",
        drift.max,
        f.acceleration / gains().kp,
        s32.max,
        p,
    );
}

#[test]
fn gough_stewart_f32_and_f64_loops() {
    let r = gough_stewart::Reference::DEMO;
    let (mut l32, mut l64) = (
        bench::gough_stewart::Loop::<f32>::new(gains(), r, Timing::KHZ),
        bench::gough_stewart::Loop::<f64>::new(gains(), r, Timing::KHZ),
    );
    let (mut t32, mut t64) = (
        bench::gough_stewart::Tracking::default(),
        bench::gough_stewart::Tracking::default(),
    );
    let mut drift = bench::gough_stewart::Tracking::default();
    for _ in 0..(SECONDS / Timing::KHZ.period) as u32 {
        let (e32, e64) = (l32.tick().expect("f32 loop"), l64.tick().expect("f64 loop"));
        t32.add(&e32);
        t64.add(&e64);
        drift.add(&core::array::from_fn(|i| e32[i] - e64[i]));
    }
    let (pr, pt) = bench::gough_stewart::predicted_max_error(gains(), &r, Timing::KHZ, SECONDS)
        .expect("estimate");
    as_predicted("gough_stewart f64 rotation", t64.rotation.max, pr);
    as_predicted("gough_stewart f64 translation", t64.translation.max, pt);
    assert!(t64.rotation.max < 1e-3 * r.angle);
    assert!(t64.translation.max < 1e-3 * 0.03);
    let (fr, ft) =
        bench::gough_stewart::rounding_floor(gains(), &r, Timing::KHZ, SECONDS).expect("floor");
    torque_is_single_precision("gough_stewart", &fr);
    let kp = gains().kp;
    within_floor(
        "gough_stewart rotation",
        drift.rotation.max,
        fr.acceleration / kp,
        t32.rotation.max,
        pr,
    );
    within_floor(
        "gough_stewart translation",
        drift.translation.max,
        ft.acceleration / kp,
        t32.translation.max,
        pt,
    );
}

/// Halving the control rate doubles the error (the hold error is first order in `h`): `f64`
/// controller, where rounding cannot blur the ratio.
#[test]
fn error_is_first_order_in_the_period() {
    let r = puma::Reference::DEMO;
    let fast = bench::puma::run::<f64>(gains(), r, Timing::KHZ, SECONDS).expect("1 kHz");
    let slow_timing = Timing {
        period: 2.0 * Timing::KHZ.period,
        substeps: 2 * Timing::KHZ.substeps,
    };
    let slow = bench::puma::run::<f64>(gains(), r, slow_timing, SECONDS).expect("500 Hz");
    let ratio = slow.max / fast.max;
    println!("puma560: 500 Hz / 1 kHz max error = {ratio:.3}");
    assert!((1.6..2.5).contains(&ratio), "{ratio}");
}

/// The firmware part, `Controller::step`, makes no heap allocation, in `f32` and in `f64`.
#[test]
fn control_step_does_not_allocate() {
    fn ticks<S: puma::Scalar + gough_stewart::Scalar>() -> (f64, u64) {
        let g = Gains::<S>::critically_damped(8.0);
        let pc = puma::Controller::<S> {
            gains: g,
            reference: puma::Reference::DEMO.cast(),
        };
        let r = gough_stewart::Reference::DEMO;
        let mut gc = gough_stewart::Controller::<S>::new(g, r.cast());
        let (q0, qd0, _) = pc.reference.at(S::from_f64(0.1));
        let (x0, u0, _) = r.at(0.1);
        gc.estimate = cast(&x0);
        let lengths: [S; 6] =
            cast(&mechanisms::gough_stewart::inverse_kinematics(&x0).expect("ik"));
        let u0: [S; 6] = cast(&u0);
        let mut sink = 0.0;
        let info = allocation_counter::measure(|| {
            for k in 0..100 {
                let t = S::from_f64(0.1 + k as f64 * 1e-6);
                sink += pc.step(t, &q0, &qd0)[0].to_f64();
                sink += gc.step(t, &lengths, &u0).expect("step")[0].to_f64();
            }
        });
        (sink, info.count_total)
    }
    // The counter sees allocations in this test binary (so a zero below means something).
    let canary = allocation_counter::measure(|| {
        std::hint::black_box(vec![0u8; 16]);
    });
    assert_eq!(canary.count_total, 1);
    let (sink, count) = ticks::<f32>();
    assert!(sink.is_finite());
    assert_eq!(count, 0, "f32");
    let (sink, count) = ticks::<f64>();
    assert!(sink.is_finite());
    assert_eq!(count, 0, "f64");
}
