//! Smoothing and differentiation of sampled joint positions (`identify` with `t, q, tau` only,
//! docs/identification.md, "Positions only"): a second-order Butterworth low-pass run forward
//! then backward (zero phase, fourth-order roll-off, gain 1/2 at the cutoff), then five-point
//! central differences for `q̇` and `q̈`. The efforts and the regressor's columns go through
//! the same filter (`identify`: Gautier's parallel filtering), so that the model and the
//! measurement see the same frequency band.

/// The coefficients `(b0, b1, b2, a1, a2)` of a second-order Butterworth low-pass with cutoff
/// `fc` at sample rate `fs` (bilinear transform with prewarping): `y_k = b0 x_k + b1 x_{k−1}
/// + b2 x_{k−2} − a1 y_{k−1} − a2 y_{k−2}`.
fn butterworth(fc: f64, fs: f64) -> [f64; 5] {
    let k = (std::f64::consts::PI * fc / fs).tan();
    let r2 = std::f64::consts::SQRT_2;
    let norm = 1.0 / (1.0 + r2 * k + k * k);
    let b0 = k * k * norm;
    [
        b0,
        2.0 * b0,
        b0,
        2.0 * (k * k - 1.0) * norm,
        (1.0 - r2 * k + k * k) * norm,
    ]
}

/// The samples after which a transient of the filter has decayed as far as an ideal
/// (analog) Butterworth's does in `periods` cutoff periods, `exp(−ζ ω_c t)` with `ζ = 1/√2`:
/// `periods · fs / fc`, or more near half the sample rate, where the bilinear transform puts
/// the poles close to `z = −1` (pole radius `√a2`, 0.80 at `fc = 0.45 fs`: 60 samples to the
/// level that three periods reach, not 7). Far below half the rate the two agree to a
/// fraction of a percent (150.0009 samples for three periods at `fc = fs / 50`), and the
/// periods are kept: a level 1 % short of the chosen one is the same level. As a float: huge
/// near or at half the rate, where the caller refuses the file as too short.
pub fn settling(fc: f64, fs: f64, periods: f64) -> f64 {
    let level = -std::f64::consts::TAU * periods / std::f64::consts::SQRT_2;
    let radius_ln = 0.5 * butterworth(fc, fs)[4].ln();
    let digital = if radius_ln < 0.0 {
        level / radius_ln
    } else {
        f64::INFINITY
    };
    let analog = periods * fs / fc;
    if digital > 1.01 * analog {
        digital
    } else {
        analog
    }
}

/// One pass of the biquad, started in the steady state of the first sample (no transient for
/// a signal that starts flat).
fn pass(c: &[f64; 5], x: &mut [f64]) {
    let [b0, b1, b2, a1, a2] = *c;
    let Some(&x0) = x.first() else { return };
    let mut z2 = (b2 - a2) * x0;
    let mut z1 = (b1 - a1) * x0 + z2;
    for v in x.iter_mut() {
        let xi = *v;
        let y = b0 * xi + z1;
        z1 = b1 * xi - a1 * y + z2;
        z2 = b2 * xi - a2 * y;
        *v = y;
    }
}

/// Zero-phase low-pass of `x` (forward, then backward). Each end is first extended by its
/// odd reflection, `2 x₀ − x_k` over the filter's settling of three cutoff periods (Gustafsson 1996, SciPy's
/// `filtfilt` padding): the extension continues the signal's value and slope, so the passes,
/// started in the steady state of the extension's first sample, meet the data without the
/// transient that a signal starting on a slope leaves (which differentiating twice amplifies:
/// on the Delta's positions-only test it cut the accelerations' worst error in the kept
/// samples from 0.25 to 2e-3 m/s² and the estimates' error tenfold).
pub fn filtfilt(x: &mut [f64], fc: f64, fs: f64) {
    let n = x.len();
    let pad = if n < 2 {
        0
    } else {
        settling(fc, fs, 3.0).ceil().min((n - 1) as f64) as usize
    };
    let mut e: Vec<f64> = Vec::with_capacity(n + 2 * pad);
    if let (Some(&first), Some(&last)) = (x.first(), x.last()) {
        e.extend((1..=pad).rev().map(|k| 2.0 * first - x[k]));
        e.extend_from_slice(x);
        e.extend((1..=pad).map(|k| 2.0 * last - x[n - 1 - k]));
    }
    let c = butterworth(fc, fs);
    pass(&c, &mut e);
    e.reverse();
    pass(&c, &mut e);
    e.reverse();
    x.copy_from_slice(&e[pad..pad + n]);
}

/// Central differences of uniformly sampled `x` (step `dt`): `(ẋ, ẍ)`, fourth order inside
/// (five points: `(−x₊₂ + 8x₊₁ − 8x₋₁ + x₋₂)/12h` and `(−x₊₂ + 16x₊₁ − 30x₀ + 16x₋₁ − x₋₂)/12h²`,
/// whose gains at `ωh` are `1 − (ωh)⁴/30` and `1 − (ωh)⁴/90` against the three-point
/// differences' `1 − (ωh)²/6` and `1 − (ωh)²/12`: 2e-9 instead of 4e-5 at 0.5 Hz and 5 ms),
/// three-point next to the ends; the two end samples take the values of their neighbours (the
/// caller drops them).
pub fn differentiate(x: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let mut d = vec![0.0; n];
    let mut dd = vec![0.0; n];
    for k in 1..n.saturating_sub(1) {
        if k >= 2 && k + 2 < n {
            d[k] = (-x[k + 2] + 8.0 * x[k + 1] - 8.0 * x[k - 1] + x[k - 2]) / (12.0 * dt);
            dd[k] = (-x[k + 2] + 16.0 * x[k + 1] - 30.0 * x[k] + 16.0 * x[k - 1] - x[k - 2])
                / (12.0 * dt * dt);
        } else {
            d[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt);
            dd[k] = (x[k + 1] - 2.0 * x[k] + x[k - 1]) / (dt * dt);
        }
    }
    if n >= 3 {
        d[0] = d[1];
        dd[0] = dd[1];
        d[n - 1] = d[n - 2];
        dd[n - 1] = dd[n - 2];
    }
    (d, dd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dc_passes_and_high_frequencies_are_cut() {
        let fs = 1000.0;
        let mut flat = vec![2.5; 200];
        filtfilt(&mut flat, 20.0, fs);
        assert!(flat.iter().all(|v| (v - 2.5).abs() < 1e-12));
        // 200 Hz through a 20 Hz cutoff: (20/200)^4 ≈ 1e-4 of the amplitude.
        let mut hf: Vec<f64> = (0..2000)
            .map(|k| (2.0 * std::f64::consts::PI * 200.0 * k as f64 / fs).sin())
            .collect();
        filtfilt(&mut hf, 20.0, fs);
        let inner = &hf[200..1800];
        assert!(inner.iter().all(|v| v.abs() < 1e-3), "{:e}", inner[500]);
    }

    /// A ramp (a signal that starts and ends on a slope) passes unchanged up to its ends,
    /// which the odd extension continues exactly: the transient where the extension starts has
    /// decayed over its three cutoff periods to 1.3e-8 at the data (bound 1e-7), where the
    /// passes started at the first and last samples leave 1.1e-2 (more than 1e-3).
    #[test]
    fn a_ramp_passes_to_its_ends() {
        let fs = 200.0;
        let mut x: Vec<f64> = (0..400).map(|k| 0.3 + 0.25 * k as f64 / fs).collect();
        let want = x.clone();
        filtfilt(&mut x, 5.0, fs);
        let worst = x
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // Unpadded, the passes started at the first and last samples.
        let c = butterworth(5.0, fs);
        let mut y = want.clone();
        pass(&c, &mut y);
        y.reverse();
        pass(&c, &mut y);
        y.reverse();
        let unpadded = y
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-7 && unpadded > 1e-3, "{worst:e} {unpadded:e}");
    }

    /// A step's transient through one pass, after `settling(fc, fs, 3)` samples, is within
    /// 30× the level an ideal filter reaches in three cutoff periods (1.6e-6; the peak of the
    /// digital response's envelope is above the analog one's), at low and high cutoffs; near
    /// half the rate the three periods alone (7 samples at `0.45 fs`) leave 5e-2. At half the
    /// rate itself (or within its rounding), the settling is longer than any file.
    #[test]
    fn the_settling_covers_the_transient_up_to_half_the_rate() {
        let fs = 1000.0;
        let level = (-std::f64::consts::TAU * 3.0 / std::f64::consts::SQRT_2).exp();
        let after = |fc: f64, n: usize| {
            let mut x = vec![1.0; n + 200];
            x[0] = 0.0;
            pass(&butterworth(fc, fs), &mut x);
            x[n..].iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max)
        };
        for fc in [5.0, 20.0, 100.0, 300.0, 450.0, 490.0] {
            let n = settling(fc, fs, 3.0).ceil() as usize;
            let left = after(fc, n);
            assert!(left < 30.0 * level, "{fc} Hz: {left:e} after {n} samples");
        }
        // Low cutoffs: the three periods themselves (the files' edges as before).
        assert_eq!(settling(20.0, fs, 3.0), 150.0);
        let three = (3.0 * fs / 450.0_f64).ceil() as usize;
        assert!(after(450.0, three) > 1e-2, "{:e}", after(450.0, three));
        for fc in [500.0, 500.0 * (1.0 - 1e-12), 500.0 * (1.0 + 1e-12)] {
            assert!(
                settling(fc, fs, 3.0) > 1e9,
                "{fc}: {}",
                settling(fc, fs, 3.0)
            );
        }
    }

    #[test]
    fn a_slow_sine_is_differentiated_within_the_band() {
        let (fs, f) = (500.0, 0.5);
        let w = 2.0 * std::f64::consts::PI * f;
        let mut x: Vec<f64> = (0..5000).map(|k| (w * k as f64 / fs).sin()).collect();
        filtfilt(&mut x, 10.0, fs);
        let (d, dd) = differentiate(&x, 1.0 / fs);
        for k in 500..4500 {
            let t = k as f64 / fs;
            assert!((d[k] - w * (w * t).cos()).abs() < 1e-3 * w, "{k}");
            assert!((dd[k] + w * w * (w * t).sin()).abs() < 1e-3 * w * w, "{k}");
        }
    }
}
