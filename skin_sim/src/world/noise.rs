//! Seeded Gaussian sensor noise, bit-reproducible across runs and platforms: SplitMix64 (Steele,
//! Lea, Flood 2014) for uniform numbers and the Box-Muller transform for normal ones. Small and
//! dependency-free; the simulation needs reproducibility, not cryptographic quality.

/// A seeded source of zero-mean Gaussian noise.
#[derive(Debug, Clone)]
pub struct Noise {
    state: u64,
    /// Second normal number of the last Box-Muller pair.
    spare: Option<f64>,
}

impl Noise {
    /// A generator from `seed`; `stream` separates the sensors of one run (same seed, other
    /// sequence), so adding a sensor does not change another's noise.
    pub fn new(seed: u64, stream: u64) -> Self {
        Noise { state: seed ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03), spare: None }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1]: never 0, so that its logarithm is finite.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `(lo, hi]`.
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A normal sample with standard deviation `std` (0: exactly 0, no draw).
    pub fn gaussian(&mut self, std: f64) -> f64 {
        if std == 0.0 {
            return 0.0;
        }
        let z = match self.spare.take() {
            Some(z) => z,
            None => {
                let (u, v) = (self.uniform(), self.uniform());
                let r = (-2.0 * u.ln()).sqrt();
                let a = std::f64::consts::TAU * v;
                self.spare = Some(r * a.sin());
                r * a.cos()
            }
        };
        std * z
    }
}

#[cfg(test)]
mod tests {
    use super::Noise;

    #[test]
    fn gaussian_has_the_requested_moments_and_repeats_with_the_seed() {
        let mut n = Noise::new(7, 1);
        let xs: Vec<f64> = (0..20_000).map(|_| n.gaussian(0.5)).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.02, "mean {mean}");
        assert!((var.sqrt() - 0.5).abs() < 0.02, "std {}", var.sqrt());
        let mut again = Noise::new(7, 1);
        assert!(xs.iter().all(|&x| x.to_bits() == again.gaussian(0.5).to_bits()));
        assert_ne!(Noise::new(7, 2).gaussian(1.0), Noise::new(7, 1).gaussian(1.0));
    }
}
