//! The last-stage limits of the resolver, as small pure functions (applied in the order
//! velocity -> position -> acceleration, see `docs/resolver.md`).

/// Scales the velocities of each kinematic chain by one factor so that every joint of the chain
/// is within its limit `vmax[i]`: the joint-space direction of each arm is kept (so is, at this
/// instant, the Cartesian direction of every point of it), unlike a per-joint clamp.
/// `chain[i]` is the chain of joint `i`; `scale` is scratch with one entry per chain.
pub(crate) fn scale_chains(v: &mut [f64], vmax: &[f64], chain: &[usize], scale: &mut [f64]) {
    scale.fill(1.0);
    for i in 0..v.len() {
        let a = v[i].abs();
        if a > vmax[i] {
            let s = &mut scale[chain[i]];
            *s = s.min(vmax[i] / a);
        }
    }
    for i in 0..v.len() {
        let s = scale[chain[i]];
        if s < 1.0 {
            v[i] *= s;
        }
    }
}

/// Position limit of one joint at position `q` in `[lower, upper]`: the component of `v` that
/// moves outward is limited to the speed from which the joint can still stop at the limit with
/// deceleration `amax` when it starts braking after this step (`v dt + v²/(2 amax) <= distance`);
/// at or past the limit it is zero. Motion inward is never limited.
#[inline]
pub(crate) fn position_limit(v: f64, q: f64, lower: f64, upper: f64, amax: f64, dt: f64) -> f64 {
    let stop = |distance: f64| amax * ((dt * dt + 2.0 * distance.max(0.0) / amax).sqrt() - dt);
    if v > 0.0 {
        v.min(stop(upper - q))
    } else if v < 0.0 {
        v.max(-stop(q - lower))
    } else {
        v
    }
}

/// Moves from `prev` towards `target` by at most `max_step` (the acceleration limit times dt).
#[inline]
pub(crate) fn rate_limit(prev: f64, target: f64, max_step: f64) -> f64 {
    prev + (target - prev).clamp(-max_step, max_step)
}

/// Scales a planar vector down to length `max` if it is longer (direction kept).
#[inline]
pub(crate) fn clamp_norm(x: [f64; 2], max: f64) -> [f64; 2] {
    let n = x[0].hypot(x[1]);
    if n > max {
        let s = max / n;
        [x[0] * s, x[1] * s]
    } else {
        x
    }
}

/// Replaces an overflowed value by the largest finite one of the same sign, so that the scalings
/// above keep working on it (finite inputs can overflow only to ±∞).
#[inline]
pub(crate) fn finite_or_max(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        f64::MAX.copysign(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolver_limits_chain_scaling_keeps_direction() {
        let mut v = [4.0, -1.0, 0.5, 3.0];
        scale_chains(&mut v, &[2.0; 4], &[0, 0, 1, 1], &mut [0.0; 2]);
        assert_eq!(v, [2.0, -0.5, 0.5 / 1.5, 2.0]);
    }

    #[test]
    fn resolver_limits_position_limit_stops_in_time() {
        let (a, dt) = (3.0, 0.008);
        assert_eq!(position_limit(1.0, 1.0, -1.0, 1.0, a, dt), 0.0);
        assert_eq!(position_limit(1.0, 1.2, -1.0, 1.0, a, dt), 0.0);
        assert_eq!(position_limit(-1.0, 1.2, -1.0, 1.0, a, dt), -1.0);
        let v = position_limit(10.0, 0.9, -1.0, 1.0, a, dt);
        assert!((v * dt + v * v / (2.0 * a) - 0.1).abs() < 1e-12, "{v}");
        assert_eq!(position_limit(5.0, 0.0, f64::NEG_INFINITY, f64::INFINITY, a, dt), 5.0);
    }
}
