//! Greedy placement of scatter-point labels: each label takes the first of eight positions
//! around its point that overlaps nothing already there, else the least-overlapping one.

/// An axis-aligned box in px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Area {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl Area {
    fn overlap(&self, other: &Area) -> f64 {
        let w = (self.x1.min(other.x1) - self.x0.max(other.x0)).max(0.0);
        let h = (self.y1.min(other.y1) - self.y0.max(other.y0)).max(0.0);
        w * h
    }

    fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }
}

/// Where a label's text goes: anchor point (baseline) and `text-anchor` value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Placement {
    /// Anchor x, px.
    pub x: f64,
    /// Baseline y, px.
    pub y: f64,
    /// `start`, `end` or `middle`.
    pub anchor: &'static str,
}

/// Half-size of the box kept clear around each point, px.
const POINT_CLEAR_PX: f64 = 5.0;

/// Positions for labels of `widths[i]` px (font `font_px`) beside `points[i]` (px), preferring
/// right, left, the four diagonals, above, below; never overlapping other points or labels when
/// a free position exists, and staying inside `bounds` when possible. Deterministic: ties go to
/// the earlier position, labels are placed in input order. `lines` are further areas to keep
/// clear (thin boxes around drawn line segments).
pub(crate) fn place_labels(
    points: &[(f64, f64)],
    widths: &[f64],
    font_px: f64,
    bounds: Area,
    lines: &[Area],
) -> Vec<Placement> {
    let clear = |&(x, y): &(f64, f64)| Area {
        x0: x - POINT_CLEAR_PX,
        y0: y - POINT_CLEAR_PX,
        x1: x + POINT_CLEAR_PX,
        y1: y + POINT_CLEAR_PX,
    };
    let mut obstacles: Vec<Area> = points.iter().map(clear).collect();
    obstacles.extend_from_slice(lines);
    let (up, down) = (-6.0, 6.0 + 0.8 * font_px);
    let candidates = [
        (7.0, 0.35 * font_px, "start"),
        (-7.0, 0.35 * font_px, "end"),
        (5.0, up, "start"),
        (5.0, down, "start"),
        (-5.0, up, "end"),
        (-5.0, down, "end"),
        (0.0, up - 2.0, "middle"),
        (0.0, down + 2.0, "middle"),
    ];
    let mut placed: Vec<Area> = Vec::new();
    let mut out = Vec::with_capacity(points.len());
    for (&(px, py), &w) in points.iter().zip(widths) {
        let mut best: Option<(f64, Placement, Area)> = None;
        for &(dx, dy, anchor) in &candidates {
            let (x, y) = (px + dx, py + dy);
            let x0 = match anchor {
                "start" => x,
                "end" => x - w,
                _ => x - w / 2.0,
            };
            let b = Area {
                x0,
                y0: y - 0.8 * font_px,
                x1: x0 + w,
                y1: y + 0.25 * font_px,
            };
            let outside = b.area() - b.overlap(&bounds);
            let score = obstacles
                .iter()
                .chain(&placed)
                .map(|o| b.overlap(o))
                .sum::<f64>()
                + 2.0 * outside;
            if best.as_ref().is_none_or(|(s, ..)| score < *s) {
                best = Some((score, Placement { x, y, anchor }, b));
            }
            if score == 0.0 {
                break;
            }
        }
        if let Some((_, placement, b)) = best {
            placed.push(b);
            out.push(placement);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOUNDS: Area = Area {
        x0: 0.0,
        y0: 0.0,
        x1: 400.0,
        y1: 300.0,
    };

    #[test]
    fn lone_label_goes_right() {
        let p = place_labels(&[(100.0, 100.0)], &[30.0], 10.0, BOUNDS, &[]);
        assert_eq!(
            p,
            [Placement {
                x: 107.0,
                y: 103.5,
                anchor: "start"
            }]
        );
    }

    #[test]
    fn labels_avoid_lines() {
        let line = Area {
            x0: 100.0,
            y0: 98.5,
            x1: 300.0,
            y1: 101.5,
        };
        let p = place_labels(&[(100.0, 100.0)], &[30.0], 10.0, BOUNDS, &[line]);
        assert_eq!(p[0].anchor, "end", "right of the point is the line");
    }

    #[test]
    fn crowded_labels_do_not_overlap_and_stay_inside() {
        let points = [(100.0, 100.0), (104.0, 102.0), (98.0, 96.0), (395.0, 150.0)];
        let widths = [40.0; 4];
        let p = place_labels(&points, &widths, 10.0, BOUNDS, &[]);
        let boxes: Vec<Area> = p
            .iter()
            .map(|pl| {
                let x0 = match pl.anchor {
                    "start" => pl.x,
                    "end" => pl.x - 40.0,
                    _ => pl.x - 20.0,
                };
                Area {
                    x0,
                    y0: pl.y - 8.0,
                    x1: x0 + 40.0,
                    y1: pl.y + 2.5,
                }
            })
            .collect();
        for i in 0..boxes.len() {
            assert_eq!(
                boxes[i].overlap(&BOUNDS),
                boxes[i].area(),
                "label {i} inside"
            );
            for j in 0..i {
                assert_eq!(boxes[i].overlap(&boxes[j]), 0.0, "labels {i} and {j}");
            }
        }
        assert_eq!(p[3].anchor, "end", "flips left at the right edge");
    }
}
