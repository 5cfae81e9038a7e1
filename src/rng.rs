//! A tiny deterministic random number generator (SplitMix64, Steele, Lea and Flood 2014).
//!
//! Tests and generated inputs need numbers that are the same on every machine, every run and
//! every thread count; an external crate's algorithm may change between versions, this one
//! cannot. SplitMix64 passes BigCrush, needs one `u64` of state and can be seeded from any value
//! (including 0). It is not cryptographic.

use std::f64::consts::TAU;

/// A seeded SplitMix64 generator with uniform and standard-normal draws.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    /// The second Box-Muller value, kept for the next [`Rng::normal`] call.
    spare_normal: Option<f64>,
}

/// The SplitMix64 increment (the golden ratio in 64-bit fixed point).
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function: a bijective mix of all 64 bits.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A seed for the independent stream number `stream` of a computation seeded with `seed`.
///
/// Parallel code gives every fixed-size chunk of work its own stream, so results do not depend
/// on how chunks are scheduled over threads.
pub fn stream_seed(seed: u64, stream: u64) -> u64 {
    mix64(seed ^ mix64(stream.wrapping_add(1).wrapping_mul(GAMMA)))
}

impl Rng {
    /// A generator seeded with `seed`; equal seeds give equal sequences.
    pub fn new(seed: u64) -> Rng {
        Rng { state: seed, spare_normal: None }
    }

    /// The next 64 uniformly distributed bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GAMMA);
        mix64(self.state)
    }

    /// Uniform in [0, 1), with 24 random bits (every value is exactly representable).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Uniform in [0, 1), with 53 random bits.
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal draw (mean 0, standard deviation 1), by the Box-Muller transform.
    pub fn normal(&mut self) -> f32 {
        self.normal_f64() as f32
    }

    /// A standard normal draw in double precision.
    pub fn normal_f64(&mut self) -> f64 {
        if let Some(z) = self.spare_normal.take() {
            return z;
        }
        // 1 - u lies in (0, 1], so the logarithm is finite.
        let radius = (-2.0 * (1.0 - self.f64()).ln()).sqrt();
        let angle = TAU * self.f64();
        self.spare_normal = Some(radius * angle.sin());
        radius * angle.cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_sequence_and_streams_differ() {
        let draws = |seed| {
            let mut rng = Rng::new(seed);
            (0..5).map(|_| rng.next_u64()).collect::<Vec<_>>()
        };
        let (a, b) = (draws(7), draws(7));
        assert_eq!(a, b);
        assert_ne!(stream_seed(7, 0), stream_seed(7, 1));
        assert_ne!(stream_seed(7, 0), stream_seed(8, 0));
    }

    #[test]
    fn uniform_and_normal_moments() {
        let mut rng = Rng::new(42);
        let n = 200_000;
        let (mut sum, mut lo, mut hi) = (0.0f64, 1.0f32, 0.0f32);
        for _ in 0..n {
            let u = rng.f32();
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
            lo = lo.min(u);
            hi = hi.max(u);
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.005);
        assert!(lo < 1e-3 && hi > 0.999);

        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let z = f64::from(rng.normal());
            assert!(z.is_finite());
            s1 += z;
            s2 += z * z;
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "variance {var}");
    }
}
