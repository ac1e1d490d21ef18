//! The 1 kHz loops track their references as well as the zero-order-hold analysis predicts
//! (see the crate docs): the largest error lies within a factor of 1.5 of
//! `(h/2) · max ‖∂FD/∂τ · τ̇_d‖∞ / kp`, it grows in proportion to the control period, and the
//! control step allocates nothing.

use control_loop::{F, Gains, Timing, gough_stewart, puma};

/// Simulated seconds per run (the references' slowest period is 5 s; 2 s covers every joint's
/// fastest excursion).
const SECONDS: F = 2.0;

fn gains() -> Gains {
    Gains::critically_damped(8.0)
}

fn as_predicted(what: &str, measured: F, predicted: F) {
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

#[test]
fn puma_error_is_the_zero_order_hold_error() {
    let c = puma::Controller {
        gains: gains(),
        reference: puma::Reference::DEMO,
    };
    let s = puma::run(&c, Timing::KHZ, SECONDS).expect("loop");
    let p = puma::predicted_max_error(&c, Timing::KHZ, SECONDS).expect("prediction");
    as_predicted("puma560", s.max, p);
    assert!(s.rms() <= s.max);
    // Small: a thousandth of the smallest amplitude.
    assert!(s.max < 1e-3 * 0.3, "{}", s.max);
}

#[test]
fn gough_stewart_error_is_the_zero_order_hold_error() {
    let r = gough_stewart::Reference::DEMO;
    let t = gough_stewart::run(gains(), &r, Timing::KHZ, SECONDS).expect("loop");
    let (pr, pt) =
        gough_stewart::predicted_max_error(gains(), &r, Timing::KHZ, SECONDS).expect("prediction");
    as_predicted("gough_stewart rotation", t.rotation.max, pr);
    as_predicted("gough_stewart translation", t.translation.max, pt);
    assert!(t.rotation.max < 1e-3 * r.angle);
    assert!(t.translation.max < 1e-3 * 0.03);
}

/// Halving the control rate doubles the error (the hold error is first order in `h`).
#[test]
fn error_is_first_order_in_the_period() {
    let c = puma::Controller {
        gains: gains(),
        reference: puma::Reference::DEMO,
    };
    let fast = puma::run(&c, Timing::KHZ, SECONDS).expect("1 kHz");
    let slow_timing = Timing {
        period: 2.0 * Timing::KHZ.period,
        substeps: 2 * Timing::KHZ.substeps,
    };
    let slow = puma::run(&c, slow_timing, SECONDS).expect("500 Hz");
    let ratio = slow.max / fast.max;
    println!("puma560: 500 Hz / 1 kHz max error = {ratio:.3}");
    assert!((1.6..2.5).contains(&ratio), "{ratio}");
}

/// The firmware part, `Controller::step`, makes no heap allocation.
#[test]
fn control_step_does_not_allocate() {
    let pc = puma::Controller {
        gains: gains(),
        reference: puma::Reference::DEMO,
    };
    let r = gough_stewart::Reference::DEMO;
    let mut gc = gough_stewart::Controller::new(gains(), r);
    let (q0, qd0, _) = pc.reference.at(0.1);
    let (x0, u0, _) = r.at(0.1);
    let lengths = mechanisms::gough_stewart::inverse_kinematics(&x0).expect("ik");
    let mut sink = 0.0;
    let info = allocation_counter::measure(|| {
        for k in 0..100 {
            let t = 0.1 + k as F * 1e-3;
            sink += pc.step(t, &q0, &qd0)[0];
            sink += gc.step(t, &lengths, &u0).expect("step")[0];
        }
    });
    assert!(sink.is_finite());
    assert_eq!(info.count_total, 0);
}
