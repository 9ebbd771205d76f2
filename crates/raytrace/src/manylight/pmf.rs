//! Discrete distributions over the VPLs: normalised probabilities and their cumulative sums
//! (accumulated in f64, stored in f32), sampled by binary search.

/// A probability mass function over `n` items.
#[derive(Clone, Debug, PartialEq)]
pub struct Pmf {
    pdf: Vec<f32>,
    cdf: Vec<f32>,
}

impl Pmf {
    /// The pmf proportional to `weights` (non-negative); `None` when they sum to 0 or are
    /// not finite.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut pdf = Vec::with_capacity(weights.len());
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0f64;
        let mut last = 0;
        for (i, w) in weights.iter().enumerate() {
            let p = w.max(0.0) / total;
            if p > 0.0 {
                last = i;
            }
            acc += p;
            pdf.push(p as f32);
            cdf.push(acc as f32);
        }
        // The last item of positive probability closes the sum, so that items of zero
        // probability after it are never drawn.
        for c in &mut cdf[last..] {
            *c = 1.0;
        }
        Some(Self { pdf, cdf })
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.pdf.len()
    }

    /// Whether it has no item.
    pub fn is_empty(&self) -> bool {
        self.pdf.is_empty()
    }

    /// Probability of item `j`.
    #[inline]
    pub fn pdf(&self, j: usize) -> f64 {
        self.pdf[j] as f64
    }

    /// The probabilities.
    pub fn pdfs(&self) -> &[f32] {
        &self.pdf
    }

    /// The cumulative sums.
    pub fn cdf(&self) -> &[f32] {
        &self.cdf
    }

    /// The item whose cumulative interval holds `u` in `[0, 1)`; never one of zero
    /// probability.
    #[inline]
    pub fn sample(&self, u: f64) -> usize {
        let u = u as f32;
        self.cdf
            .partition_point(|c| *c <= u)
            .min(self.cdf.len() - 1)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * self.pdf.len()
    }
}

/// Draws from a short list of `(item, probability)` (probabilities summing to 1) by
/// inversion with `u` in `[0, 1)`; the last item when rounding leaves `u` past the sum, `None`
/// for an empty list.
#[inline]
pub fn sample_list(list: &[(usize, f64)], u: f64) -> Option<usize> {
    let mut acc = 0.0;
    for &(item, q) in list {
        acc += q;
        if u < acc {
            return Some(item);
        }
    }
    list.last().map(|e| e.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampling_follows_the_weights_and_skips_zeros() {
        let p = Pmf::new(&[0.0, 1.0, 0.0, 3.0, 0.0]).unwrap();
        assert_eq!(p.pdfs(), &[0.0, 0.25, 0.0, 0.75, 0.0]);
        assert_eq!(p.cdf(), &[0.0, 0.25, 0.25, 1.0, 1.0]);
        let mut counts = [0usize; 5];
        for k in 0..10_000 {
            counts[p.sample((k as f64 + 0.5) / 10_000.0)] += 1;
        }
        assert_eq!(counts, [0, 2500, 0, 7500, 0]);
        // The short lists: the same inversion over (item, probability) pairs.
        let list = [(7, 0.25), (2, 0.0), (9, 0.75)];
        let mut hits = std::collections::HashMap::new();
        for k in 0..10_000 {
            *hits
                .entry(sample_list(&list, (k as f64 + 0.5) / 10_000.0).unwrap())
                .or_insert(0) += 1;
        }
        assert_eq!((hits[&7], hits.get(&2), hits[&9]), (2500, None, 7500));
        assert_eq!(sample_list(&list, 1.0 - 1e-17), Some(9));
        assert_eq!(sample_list(&[], 0.5), None);
        assert_eq!(p.sample(0.0), 1);
        assert_eq!(p.sample(0.999_999_9), 3);
        assert!(Pmf::new(&[0.0, 0.0]).is_none());
        assert!(Pmf::new(&[f64::NAN]).is_none());
    }
}
