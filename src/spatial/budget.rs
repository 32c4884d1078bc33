//! Keeping what a refinement rebuilds inside a cell (cuts, quadtrees)
//! within a structure's memory budget.
//!
//! A refinement first asks every cell's content what it will grow to
//! ([`Growth`]). When that, the spatial tree and what no refinement can
//! shrink fit the budget, nothing changes. Otherwise every cell's growth is
//! scaled down by the same factor ([`content_scale`]): each cut or quadtree
//! is rebuilt with at most `floor(scale * nodes)` nodes, coarsening its
//! threshold (`sigma`, `rho`) until it fits. The cells keep their relative
//! shares; the spatial split pass then spends only what is left.

/// What one part of a cell (a cut, a quadtree) will hold after its
/// refinement at the configured threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Growth {
    /// Heap bytes it holds whatever its node count (sampling copies that
    /// are already decided, fixed sums).
    pub(crate) fixed: usize,
    /// Nodes it will have.
    pub(crate) nodes: usize,
    /// Heap bytes per node.
    pub(crate) per_node: usize,
}

impl Growth {
    /// Its node cap under `scale` (`None`: no cap).
    pub(crate) fn cap(&self, scale: Option<f64>) -> Option<usize> {
        scale.map(|s| (self.nodes as f64 * s) as usize)
    }
}

/// The factor every cell's node count is scaled by so that
/// `spatial_bytes` plus every part's growth (`fixed + nodes * per_node`) stays within
/// `max_bytes`; `None` when it fits as it is (or there is no budget).
pub(crate) fn content_scale(
    max_bytes: Option<usize>,
    spatial_bytes: usize,
    parts: impl Iterator<Item = Growth>,
) -> Option<f64> {
    let budget = max_bytes?;
    let (mut fixed, mut grown) = (0usize, 0usize);
    for g in parts {
        fixed = fixed.saturating_add(g.fixed);
        grown = grown.saturating_add(g.nodes.saturating_mul(g.per_node));
    }
    let available = budget.saturating_sub(spatial_bytes).saturating_sub(fixed);
    (grown > available).then(|| available as f64 / grown as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_only_when_over() {
        let g = |nodes| Growth {
            fixed: 10,
            nodes,
            per_node: 4,
        };
        // 100 + 2 * 10 + (50 + 50) * 4 = 520.
        let parts = [g(50), g(50)];
        assert_eq!(content_scale(None, 100, parts.into_iter()), None);
        assert_eq!(content_scale(Some(520), 100, parts.into_iter()), None);
        let s = content_scale(Some(320), 100, parts.into_iter()).unwrap();
        assert_eq!(s, 0.5);
        assert_eq!(g(50).cap(Some(s)), Some(25));
        // Nothing left at all: every part down to its minimum.
        assert_eq!(content_scale(Some(50), 100, parts.into_iter()), Some(0.0));
    }
}
