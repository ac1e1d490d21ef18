//! The SVG heat map of `map` (plotters, SVG backend only: no fonts, no bitmaps).
//!
//! One filled cell per grid point, coloured by the value (viridis), with a colour bar. Points
//! without a value are drawn in fixed colours named in the legend: singular (the runtime returned
//! `Err(Singular)` at a leg or parallel singularity) black, unreachable (`Site::Reach`) light
//! grey, invalid (the matrix failed the index checks) red.

use plotters::prelude::*;

use super::Failure;

/// Colour of singular points.
pub const SINGULAR: RGBColor = RGBColor(0, 0, 0);
/// Colour of unreachable points.
pub const UNREACHABLE: RGBColor = RGBColor(215, 215, 215);
/// Colour of points whose matrix failed the checks.
pub const INVALID: RGBColor = RGBColor(220, 30, 30);

/// A heat map to draw.
pub struct HeatMap<'a> {
    /// First line of the caption.
    pub title: &'a str,
    /// A smaller second line (the matrix and the index definition, with the weights).
    pub subtitle: &'a str,
    /// Horizontal axis label.
    pub x_label: &'a str,
    /// Vertical axis label.
    pub y_label: &'a str,
    /// Grid values along x (ascending).
    pub xs: Vec<f64>,
    /// Grid values along y (ascending).
    pub ys: Vec<f64>,
    /// `values[j * xs.len() + i]` at `(xs[i], ys[j])`.
    pub values: &'a [Result<f64, Failure>],
    /// Colour by log10 of the value.
    pub log: bool,
}

/// Viridis, piecewise linear through nine of its samples; `t` in `[0, 1]`.
pub fn viridis(t: f64) -> RGBColor {
    const P: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (P.len() - 1) as f64;
    let k = (x.floor() as usize).min(P.len() - 2);
    let f = x - k as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    RGBColor(
        mix(P[k].0, P[k + 1].0),
        mix(P[k].1, P[k + 1].1),
        mix(P[k].2, P[k + 1].2),
    )
}

fn cell_edges(v: &[f64]) -> Vec<f64> {
    let n = v.len();
    let mut e = Vec::with_capacity(n + 1);
    let h0 = if n > 1 { v[1] - v[0] } else { 1.0 };
    e.push(v[0] - 0.5 * h0);
    for i in 0..n.saturating_sub(1) {
        e.push(0.5 * (v[i] + v[i + 1]));
    }
    let h1 = if n > 1 { v[n - 1] - v[n - 2] } else { 1.0 };
    e.push(v[n - 1] + 0.5 * h1);
    e
}

impl HeatMap<'_> {
    /// The SVG text (written by the caller through `write_output`, so that a failed write never
    /// leaves half a drawing in place).
    pub fn render(&self) -> Result<String, String> {
        let mut svg = String::new();
        self.draw(&mut svg).map_err(|e| e.to_string())?;
        Ok(svg)
    }

    fn draw(&self, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
        let tf = |v: f64| if self.log { v.log10() } else { v };
        let shown: Vec<f64> = self
            .values
            .iter()
            .filter_map(|r| r.as_ref().ok().map(|v| tf(*v)))
            .filter(|v| v.is_finite())
            .collect();
        let (lo, hi) = shown
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let (lo, hi) = if lo.is_finite() && hi > lo {
            (lo, hi)
        } else if lo.is_finite() {
            (lo - 0.5, lo + 0.5)
        } else {
            (0.0, 1.0)
        };

        let root = SVGBackend::with_string(out, (860, 680)).into_drawing_area();
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(70);
        head.draw(&Text::new(
            self.title.to_string(),
            (10, 8),
            ("sans-serif", 22).into_font(),
        ))?;
        // The definition can be long: wrap it at about 120 characters.
        let mut line = String::new();
        let mut y = 36;
        for word in self.subtitle.split(' ') {
            if line.len() + word.len() > 125 {
                head.draw(&Text::new(
                    line.clone(),
                    (10, y),
                    ("sans-serif", 12).into_font(),
                ))?;
                line.clear();
                y += 15;
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        head.draw(&Text::new(line, (10, y), ("sans-serif", 12).into_font()))?;

        let (plot, side) = body.split_horizontally(700);
        let xe = cell_edges(&self.xs);
        let ye = cell_edges(&self.ys);
        let mut chart = ChartBuilder::on(&plot)
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .label_style(("sans-serif", 13))
            .draw()?;
        let nx = self.xs.len();
        chart.draw_series(self.values.iter().enumerate().map(|(k, r)| {
            let (i, j) = (k % nx, k / nx);
            let colour = match r {
                Ok(v) => viridis((tf(*v) - lo) / (hi - lo)),
                Err(Failure::Singular(_)) => SINGULAR,
                Err(Failure::Unreachable) => UNREACHABLE,
                Err(Failure::Invalid(_)) => INVALID,
            };
            Rectangle::new([(xe[i], ye[j]), (xe[i + 1], ye[j + 1])], colour.filled())
        }))?;

        // Colour bar and legend.
        let bar_top = 30;
        let bar_h = 380;
        let steps = 64;
        for s in 0..steps {
            let t = 1.0 - (s as f64 + 0.5) / steps as f64;
            let y0 = bar_top + s * bar_h / steps;
            let y1 = bar_top + (s + 1) * bar_h / steps;
            side.draw(&Rectangle::new(
                [(20, y0), (50, y1 + 1)],
                viridis(t).filled(),
            ))?;
        }
        let label = |v: f64| {
            let v = if self.log { 10f64.powf(v) } else { v };
            super::map::fmt_g(v)
        };
        for s in 0..=4 {
            let t = s as f64 / 4.0;
            let y = bar_top + ((1.0 - t) * bar_h as f64) as i32;
            side.draw(&Text::new(
                label(lo + t * (hi - lo)),
                (56, y - 6),
                ("sans-serif", 12).into_font(),
            ))?;
        }
        side.draw(&Text::new(
            if self.log { "(log scale)" } else { "(linear)" },
            (20, bar_top + bar_h + 8),
            ("sans-serif", 12).into_font(),
        ))?;
        let legend: [(RGBColor, &str); 3] = [
            (SINGULAR, "singular"),
            (UNREACHABLE, "unreachable"),
            (INVALID, "invalid"),
        ];
        for (k, (c, name)) in legend.iter().enumerate() {
            let y = bar_top + bar_h + 40 + 22 * k as i32;
            side.draw(&Rectangle::new([(20, y), (36, y + 14)], c.filled()))?;
            side.draw(&Rectangle::new(
                [(20, y), (36, y + 14)],
                BLACK.stroke_width(1),
            ))?;
            side.draw(&Text::new(
                name.to_string(),
                (42, y),
                ("sans-serif", 12).into_font(),
            ))?;
        }
        root.present()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
    }

    #[test]
    fn edges_surround_the_points() {
        let e = cell_edges(&[0.0, 1.0, 2.0]);
        assert_eq!(e, vec![-0.5, 0.5, 1.5, 2.5]);
    }
}
