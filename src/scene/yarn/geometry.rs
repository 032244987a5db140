//! The yarns' start geometry: each `[[yarns]]` entry expanded into its
//! copies' vertex positions (straight lines or resampled polylines) and the
//! start velocities.

use super::*;

impl YarnScene {
    /// All yarn curves (one per copy), each resampled to its vertex count.
    pub fn curves(&self) -> Vec<Vec<Vec2>> {
        self.yarns
            .iter()
            .flat_map(|y| y.curves().expect("validated scene"))
            .collect()
    }

    /// Initial velocity of each yarn curve, in the order of [`YarnScene::curves`].
    pub fn curve_velocities(&self) -> Vec<Vec2> {
        self.yarns
            .iter()
            .flat_map(|y| std::iter::repeat_n(Vec2::from(y.velocity), y.count as usize))
            .collect()
    }
}

impl YarnSpec {
    /// A straight yarn from `start` to `end` with `vertices` vertices.
    pub fn straight(start: [f64; 2], end: [f64; 2], vertices: u32) -> Self {
        YarnSpec {
            start: Some(start),
            end: Some(end),
            vertices,
            count: 1,
            ..Default::default()
        }
    }

    /// The control polyline of the first copy.
    fn polyline(&self) -> Result<Vec<Vec2>, String> {
        match (
            &self.points,
            self.start,
            self.end,
            self.direction,
            self.length,
        ) {
            (Some(pts), None, None, None, None) => {
                if pts.len() < 2 {
                    return Err("`points` needs at least two points".into());
                }
                if pts.iter().flatten().any(|v| !v.is_finite()) {
                    return Err("`points` must be finite".into());
                }
                Ok(pts.iter().map(|&p| Vec2::from(p)).collect())
            }
            (None, Some(s), Some(e), None, None) => Ok(vec![s.into(), e.into()]),
            (None, Some(s), None, Some(d), Some(l)) => {
                let d = Vec2::from(d);
                let n = d.norm();
                if n == 0.0 {
                    return Err("`direction` must not be zero".into());
                }
                let s = Vec2::from(s);
                Ok(vec![s, s + d * (l / n)])
            }
            _ => Err(
                "give either `points`, or `start` and `end`, or `start`, `direction` and `length`"
                    .into(),
            ),
        }
    }

    /// The points of the control polyline as the entry gives them: the
    /// field (`start`, `end`, `points[2]`, or `length` for the end of
    /// `start`, `direction` and `length`), the words of a message before
    /// the point (`ends at`), and the point in m. Empty when the geometry is invalid.
    pub(super) fn control_points(&self) -> Vec<(String, &'static str, Vec2)> {
        let Ok(poly) = self.polyline() else {
            return Vec::new();
        };
        if self.points.is_some() {
            return poly
                .iter()
                .enumerate()
                .map(|(k, p)| (format!("points[{k}]"), "passes through", *p))
                .collect();
        }
        let end = if self.end.is_some() {
            ("end".to_string(), "ends at", poly[1])
        } else {
            (
                "length".to_string(),
                "ends (start + length * direction) at",
                poly[1],
            )
        };
        vec![("start".to_string(), "starts at", poly[0]), end]
    }

    /// The vertex positions of every copy.
    pub fn curves(&self) -> Result<Vec<Vec<Vec2>>, String> {
        let poly = self.polyline()?;
        let curve = resample(&poly, self.vertices as usize)?;
        let step = Vec2::from(self.spacing);
        Ok((0..self.count)
            .map(|c| curve.iter().map(|p| p + step * c as f64).collect())
            .collect())
    }
}

/// `n` points equally spaced by arc length along the polyline `poly`.
fn resample(poly: &[Vec2], n: usize) -> Result<Vec<Vec2>, String> {
    let seg: Vec<f64> = poly.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let total: f64 = seg.iter().sum();
    if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err("the yarn has zero length".into());
    }
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    let mut acc = 0.0;
    for i in 0..n {
        let s = total * i as f64 / (n - 1) as f64;
        while k + 1 < seg.len() && acc + seg[k] < s {
            acc += seg[k];
            k += 1;
        }
        let t = if seg[k] > 0.0 {
            ((s - acc) / seg[k]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(poly[k] + (poly[k + 1] - poly[k]) * t);
    }
    Ok(out)
}
