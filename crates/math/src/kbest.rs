//! The bounded, sorted list of the `k` nearest candidates that the kd-tree queries
//! ([`crate::knn`]) and the grid k-nearest-neighbour graph ([`crate::knn_graph`]) both fill.
//! Ties are broken by point index, so every search that offers the same candidates keeps the
//! same `k`, whatever the order it finds them in.

/// The `k` best candidates `(squared distance, index)` so far, sorted, nearest first.
pub(crate) struct Best {
    pub(crate) k: usize,
    pub(crate) items: Vec<(f64, u32)>,
}

impl Best {
    pub(crate) fn new(k: usize) -> Self {
        Self {
            k,
            items: Vec::with_capacity(k + 1),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.items.clear();
    }

    /// The squared distance a candidate must not exceed to enter.
    #[inline]
    pub(crate) fn bound(&self) -> f64 {
        if self.items.len() < self.k {
            f64::INFINITY
        } else {
            self.items[self.k - 1].0
        }
    }

    #[inline]
    pub(crate) fn offer(&mut self, d2: f64, id: u32) {
        let full = self.items.len() == self.k;
        if full {
            let w = self.items[self.k - 1];
            if d2 > w.0 || (d2 == w.0 && id > w.1) {
                return;
            }
            self.items.pop();
        }
        let mut pos = self.items.len();
        while pos > 0 {
            let p = self.items[pos - 1];
            if p.0 < d2 || (p.0 == d2 && p.1 < id) {
                break;
            }
            pos -= 1;
        }
        self.items.insert(pos, (d2, id));
    }
}
