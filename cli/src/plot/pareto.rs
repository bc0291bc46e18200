//! The Pareto front of a speed-versus-accuracy table.

/// Indices of the points not dominated when minimising both coordinates (no other point is at
/// least as good in both and better in one), ordered by increasing x. Points with a NaN/inf
/// coordinate are ignored; of identical points only the first is kept.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        let (p, q) = (points[a], points[b]);
        p.0.total_cmp(&q.0)
            .then(p.1.total_cmp(&q.1))
            .then(a.cmp(&b))
    });
    let mut best_y = f64::INFINITY;
    let mut front = Vec::new();
    for i in order {
        if points[i].1 < best_y {
            best_y = points[i].1;
            front.push(i);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_minimises_both() {
        let pts = [
            (100.0, 1e-3),
            (10.0, 1e-1),
            (1000.0, 1e-3),
            (50.0, 1e-2),
            (f64::NAN, 1e-9),
            (1e5, 1e-9),
            (10.0, 1e-1),
            (60.0, 2e-2),
        ];
        assert_eq!(pareto_front(&pts), [1, 3, 0, 5]);
        assert!(pareto_front(&[]).is_empty());
    }
}
