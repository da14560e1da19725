//! Counter-based random streams: case `k`'s numbers depend on `(seed, k, stream)` only.
//!
//! Each stream is a SplitMix64 sequence (Steele, Lea & Flood 2014: a Weyl counter passed
//! through a 64-bit mixing function) whose starting counter is the first 8 bytes of
//! SHA-256(`seed`, `k`, `stream`, little endian). So the draws of case `k` are the same on any
//! machine, with any number of threads or shards, and do not depend on the other cases: there
//! is no shared generator to advance.

use sha2::{Digest, Sha256};

/// Golden-ratio Weyl increment of SplitMix64.
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// A random stream of one case (see the module doc).
#[derive(Debug, Clone)]
pub struct Stream {
    counter: u64,
}

/// SplitMix64's output function (a bijective mixer of the counter).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Stream {
    /// The stream `stream` of case `case` of a study seeded with `seed`.
    pub fn new(seed: u64, case: u64, stream: u64) -> Stream {
        let mut h = Sha256::new();
        h.update(seed.to_le_bytes());
        h.update(case.to_le_bytes());
        h.update(stream.to_le_bytes());
        let d = h.finalize();
        let mut b = [0u8; 8];
        b.copy_from_slice(&d[..8]);
        Stream {
            counter: u64::from_le_bytes(b),
        }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.counter = self.counter.wrapping_add(GAMMA);
        mix(self.counter)
    }

    /// Uniform in `[0, 1)`, 53 random bits.
    pub fn uniform01(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[low, high)`.
    pub fn uniform(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.uniform01()
    }

    /// Standard normal (Box-Muller, the cosine branch; two uniforms per draw).
    pub fn standard_normal(&mut self) -> f64 {
        // 1 - u is in (0, 1]: the logarithm is finite.
        let u1 = 1.0 - self.uniform01();
        let u2 = self.uniform01();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// Normal with mean `mean` and standard deviation `std`.
    pub fn normal(&mut self, mean: f64, std: f64) -> f64 {
        mean + std * self.standard_normal()
    }

    /// Normal(`mean`, `std`) conditioned on `[low, high]`, by rejection. After 10,000
    /// rejections (an interval far in a tail, which validation warns against) it falls back to
    /// a uniform draw in `[low, high]`, so a draw always ends.
    pub fn truncated_normal(&mut self, mean: f64, std: f64, low: f64, high: f64) -> f64 {
        for _ in 0..10_000 {
            let x = self.normal(mean, std);
            if (low..=high).contains(&x) {
                return x;
            }
        }
        self.uniform(low, high)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_numbers_other_inputs_other_numbers() {
        let a: Vec<u64> = (0..5)
            .map(|_| 0)
            .scan(Stream::new(7, 3, 1), |s, _| Some(s.next_u64()))
            .collect();
        let b: Vec<u64> = (0..5)
            .map(|_| 0)
            .scan(Stream::new(7, 3, 1), |s, _| Some(s.next_u64()))
            .collect();
        assert_eq!(a, b);
        for (seed, case, stream) in [(8, 3, 1), (7, 4, 1), (7, 3, 2)] {
            assert_ne!(Stream::new(seed, case, stream).next_u64(), a[0]);
        }
    }

    /// Moments of 200,000 draws: the standard error of a mean of n unit-variance draws is
    /// 1/sqrt(n) = 0.0022, so 0.01 is a > 4-sigma bound; the variance's is sqrt(2/n) = 0.003.
    #[test]
    fn moments_of_the_distributions() {
        let n = 200_000;
        let mut s = Stream::new(1, 0, 0);
        let xs: Vec<f64> = (0..n).map(|_| s.standard_normal()).collect();
        let m = xs.iter().sum::<f64>() / n as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
        assert!(m.abs() < 0.01, "mean {m}");
        assert!((v - 1.0).abs() < 0.015, "variance {v}");
        let us: Vec<f64> = (0..n).map(|_| s.uniform(2.0, 4.0)).collect();
        assert!(us.iter().all(|u| (2.0..4.0).contains(u)));
        let mu = us.iter().sum::<f64>() / n as f64;
        // uniform(2, 4): mean 3, std 2/sqrt(12) = 0.577, standard error 0.0013
        assert!((mu - 3.0).abs() < 0.006, "uniform mean {mu}");
        let ts: Vec<f64> = (0..n)
            .map(|_| s.truncated_normal(0.0, 1.0, -1.0, 1.0))
            .collect();
        assert!(ts.iter().all(|t| (-1.0..=1.0).contains(t)));
        // Var of N(0,1) truncated to [-1, 1]: 1 - 2 phi(1) / (2 Phi(1) - 1) = 0.29112
        let vt = ts.iter().map(|t| t * t).sum::<f64>() / n as f64;
        assert!((vt - 0.29112).abs() < 0.005, "truncated variance {vt}");
    }
}
