//! The damping that returns a restitution e: `beta(e)` for the law whose normal force may
//! turn attractive at the end of contact, and the `beta` that returns e under the clamp
//! `Fn >= 0`.
//!
//! Both normal laws reduce to one equation. The linear spring-dashpot, in units
//! `m* = kn = 1` and with `b = |beta|`: `x'' + 2 b x' + x = 0`. Hertz with the damping
//! `gn = 2 sqrt(5/6) b sqrt(Sn m*)`, in units `m* = 4/3 E* sqrt(R*) = 1`:
//! `x'' = -x^(3/2) - sqrt(5) b x^(1/4) x'`; with `w = (2/sqrt(5)) x^(5/4)` and the time
//! `tau` that runs as `dtau/dt = (sqrt(5)/2) x^(1/4)`, it becomes `w'' + 2 b w' + w = 0`,
//! the spring's, with `dw/dtau = v` (the normal speed) at every instant. So the two laws
//! part at the same speed for the same b (docs/model.md):
//!
//! - without the clamp the contact ends at `x = 0`: `e = exp(-pi b / sqrt(1 - b^2))`,
//!   which `beta(e) = ln e / sqrt(ln^2 e + pi^2)` inverts (and b >= 1 never parts: e = 0);
//! - with the clamp it ends where the force `w + 2 b w'` reaches 0 (the grains then part at
//!   the speed they have): `e = exp(-2 b acos(b) / sqrt(1 - b^2))` for b < 1,
//!   `exp(-2 b acosh(b) / sqrt(b^2 - 1))` for b > 1, `exp(-2)` at b = 1, and
//!   `~ 1 / (4 b^2)` as b grows: e -> 0 only as b -> infinity. The default beta(e) then
//!   returns more than e (0.2 gives 0.325, 0.8 gives 0.808); [`clamped_beta`] inverts
//!   this one instead (`model.damping = "clamped_restitution"`).
//!
//! tests/restitution_clamped.rs checks the mapping by integrating the Hertz equation
//! numerically, and both laws in the engine's own head-on impacts.

use std::f64::consts::PI;

/// `beta(e) = ln e / sqrt(ln^2 e + pi^2)`: negative for e < 1, zero for e = 1, and -1 at
/// e = 0 (its limit: critical damping, where the grains never part).
pub fn beta(restitution: f64) -> f64 {
    if restitution == 0.0 {
        return -1.0;
    }
    let l = restitution.ln();
    l / (l * l + PI * PI).sqrt()
}

/// The restitution e whose `beta(e)` is `beta` (`exp(pi beta / sqrt(1 - beta^2))`), for
/// -1 < beta <= 0; `None` otherwise (beta(e) > -1 for every e > 0).
pub fn restitution_of_beta(beta: f64) -> Option<f64> {
    (beta > -1.0 && beta <= 0.0).then(|| (PI * beta / ((1.0 - beta) * (1.0 + beta)).sqrt()).exp())
}

/// The restitution that the clamped law (either normal law) realises in continuous time
/// with damping `b = |beta| >= 0`.
pub fn clamped_restitution(b: f64) -> f64 {
    if b <= 0.0 {
        return 1.0;
    }
    // acos(b) / sqrt(1 - b^2), continued past b = 1 as acosh(b) / sqrt(b^2 - 1); both
    // written without cancellation near b = 1.
    let g = if b < 1.0 {
        b.acos() / ((1.0 - b) * (1.0 + b)).sqrt()
    } else if b > 1.0 {
        b.acosh() / ((b - 1.0) * (b + 1.0)).sqrt()
    } else {
        1.0
    };
    (-2.0 * b * g).exp()
}

/// The `beta <= 0` with which the clamped law realises `e` in continuous time; `None` for
/// e = 0 (it needs infinite damping) or an e outside (0, 1].
pub fn clamped_beta(e: f64) -> Option<f64> {
    if !(e > 0.0 && e <= 1.0) {
        return None;
    }
    if e == 1.0 {
        return Some(0.0);
    }
    // ln e(b) falls from 0 at b = 0 without bound, monotonically: bracket it, then regula
    // falsi (Illinois) on ln e(b) - ln e to the last bits of b.
    let target = e.ln();
    let g = |b: f64| clamped_restitution(b).ln() - target;
    let (mut lo, mut glo) = (0.0f64, -target);
    let mut hi = 1.0f64;
    let mut ghi = g(hi);
    while ghi > 0.0 {
        (lo, glo) = (hi, ghi);
        hi *= 2.0;
        ghi = g(hi);
    }
    let mut side = 0i8;
    for _ in 0..200 {
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let mid = (lo * ghi - hi * glo) / (ghi - glo);
        if !(mid > lo && mid < hi) {
            break;
        }
        let gm = g(mid);
        if gm == 0.0 {
            return Some(-mid);
        }
        if gm > 0.0 {
            (lo, glo) = (mid, gm);
            if side == 1 {
                ghi *= 0.5;
            }
            side = 1;
        } else {
            (hi, ghi) = (mid, gm);
            if side == -1 {
                glo *= 0.5;
            }
            side = -1;
        }
    }
    Some(-0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clamped_closed_form_is_continuous_at_critical_damping() {
        let e = (-2.0f64).exp();
        assert!((clamped_restitution(1.0 - 1e-9) - e).abs() < 1e-8);
        assert!((clamped_restitution(1.0 + 1e-9) - e).abs() < 1e-8);
    }

    #[test]
    fn small_damping_barely_feels_the_clamp_and_large_tends_to_a_quarter_over_b_squared() {
        // b -> 0: the unclamped exp(-pi b / sqrt(1 - b^2)) to first order in b (both
        // are 1 - pi b + O(b^2)); b -> infinity: 1 / (4 b^2) (1 + O(ln b / b^2)).
        let b = 1e-5;
        let free = (-PI * b / (1.0 - b * b).sqrt()).exp();
        assert!((clamped_restitution(b) - free).abs() < 10.0 * b * b);
        let b = 1e4;
        assert!((clamped_restitution(b) * 4.0 * b * b - 1.0).abs() < 1e-6);
    }

    #[test]
    fn clamped_beta_inverts_the_closed_form() {
        for e in [1e-6, 0.01, 0.1, 0.135, 0.2, 0.5, 0.8, 0.99, 1.0 - 1e-12] {
            let b = -clamped_beta(e).unwrap();
            // The closed form's own rounding: a few ulps of its exponent, ln e.
            let tol = 8.0 * f64::EPSILON * e * (1.0 + e.ln().abs());
            assert!((clamped_restitution(b) - e).abs() <= tol, "{e}: {}", clamped_restitution(b) - e);
        }
        assert_eq!(clamped_beta(0.0), None);
        assert_eq!(clamped_beta(1.0), Some(0.0));
    }
}
