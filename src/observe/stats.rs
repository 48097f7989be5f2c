//! Block averages and confidence intervals for time series of correlated samples.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Mean with a 95% confidence interval from block averages.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Estimate {
    pub mean: f64,
    /// Half-width of the 95% confidence interval.
    pub ci95: f64,
    /// Number of blocks used.
    pub blocks: usize,
}

/// Split `x` into `blocks` consecutive blocks, average each, and take the Student-t 95%
/// interval of the block means (blocks long enough to be nearly independent).
pub fn block_average(x: &[f64], blocks: usize) -> Estimate {
    let blocks = blocks.min(x.len()).max(1);
    let len = x.len() / blocks;
    if len == 0 {
        return Estimate { mean: f64::NAN, ci95: f64::NAN, blocks: 0 };
    }
    let means: Vec<f64> = (0..blocks).map(|b| x[b * len..(b + 1) * len].iter().sum::<f64>() / len as f64).collect();
    let mean = means.iter().sum::<f64>() / blocks as f64;
    if blocks < 2 {
        return Estimate { mean, ci95: f64::INFINITY, blocks };
    }
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64;
    let t = StudentsT::new(0.0, 1.0, (blocks - 1) as f64).expect("dof >= 1").inverse_cdf(0.975);
    Estimate { mean, ci95: t * (var / blocks as f64).sqrt(), blocks }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_of_constant_series_is_zero_and_t_quantile_is_right() {
        let e = block_average(&[2.0; 100], 10);
        assert_eq!(e.mean, 2.0);
        assert_eq!(e.ci95, 0.0);
        // Two blocks of means 0 and 1: s = 0.7071, t(0.975, 1) = 12.706.
        let e = block_average(&[0.0, 0.0, 1.0, 1.0], 2);
        assert!((e.ci95 - 12.706 * 0.5).abs() < 1e-3, "{e:?}");
    }
}
