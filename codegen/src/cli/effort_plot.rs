//! The SVG of `identify --plot` (plotters, SVG backend only, as the heat map of [`super::svg`]):
//! per actuator (or joint) one panel with the measured effort and the effort the identified
//! base parameters predict (`Y π̂`) over the samples, the residual's RMS in the panel's title.
//! Each panel draws its two curves as one `<polyline>` each, stroked in [`MEASURED`] and
//! [`PREDICTED`] (the axes' polylines are black); the bytes depend only on the data.

use std::path::Path;

use plotters::prelude::*;

/// Colour of the measured efforts.
pub const MEASURED: RGBColor = RGBColor(150, 150, 150);
/// Colour of the predicted efforts.
pub const PREDICTED: RGBColor = RGBColor(214, 96, 20);

/// One panel: an effort's name, its measured and predicted values at the samples.
pub struct Panel {
    /// The joint's name.
    pub name: String,
    /// Measured efforts.
    pub measured: Vec<f64>,
    /// Predicted efforts `Y π̂`.
    pub predicted: Vec<f64>,
}

impl Panel {
    /// RMS of `measured − predicted`.
    pub fn residual_rms(&self) -> f64 {
        let n = self.measured.len().max(1) as f64;
        let s: f64 = self
            .measured
            .iter()
            .zip(&self.predicted)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        (s / n).sqrt()
    }
}

/// The plot.
pub struct EffortPlot<'a> {
    /// Caption.
    pub title: &'a str,
    /// The horizontal axis' label (`t (s)` or `sample`).
    pub x_label: &'a str,
    /// Abscissae of the samples (time, or the sample index).
    pub xs: &'a [f64],
    /// One panel per effort.
    pub panels: &'a [Panel],
}

/// The range of `v` with a 5 % margin (a unit range around a constant).
fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1.0)
    };
    (lo - pad, hi + pad)
}

impl EffortPlot<'_> {
    /// The SVG text.
    pub fn svg(&self) -> Result<String, String> {
        let mut out = String::new();
        self.draw(&mut out).map_err(|e| e.to_string())?;
        Ok(out)
    }

    /// Write the SVG file (unchanged bytes are not rewritten).
    pub fn write(&self, path: &Path) -> Result<(), String> {
        let svg = self.svg().map_err(|e| format!("{}: {e}", path.display()))?;
        super::write_output(path, &svg)
    }

    fn draw(&self, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
        let panel_h = 220u32;
        let head_h = 60u32;
        let height = head_h + panel_h * self.panels.len().max(1) as u32;
        let root = SVGBackend::with_string(out, (900, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(head_h);
        head.draw(&Text::new(
            self.title.to_string(),
            (10, 8),
            ("sans-serif", 20).into_font(),
        ))?;
        for (k, (c, what)) in [(MEASURED, "measured"), (PREDICTED, "predicted (Y π̂)")]
            .iter()
            .enumerate()
        {
            let x = 10 + 170 * k as i32;
            head.draw(&Rectangle::new([(x, 40), (x + 24, 43)], c.filled()))?;
            head.draw(&Text::new(
                what.to_string(),
                (x + 30, 34),
                ("sans-serif", 13).into_font(),
            ))?;
        }
        let areas = body.split_evenly((self.panels.len().max(1), 1));
        let (x0, x1) = range(self.xs.iter().copied());
        let (x0, x1) = if self.xs.len() > 1 {
            (self.xs[0], self.xs[self.xs.len() - 1].max(x0))
        } else {
            (x0, x1)
        };
        for (p, area) in self.panels.iter().zip(&areas) {
            let (y0, y1) = range(p.measured.iter().chain(&p.predicted).copied());
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!("{}: residual RMS {:.4e}", p.name, p.residual_rms()),
                    ("sans-serif", 14),
                )
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, y0..y1)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(self.x_label)
                .y_desc("effort (N·m or N)")
                .label_style(("sans-serif", 11))
                .draw()?;
            let xy = |v: &[f64]| -> Vec<(f64, f64)> {
                self.xs.iter().copied().zip(v.iter().copied()).collect()
            };
            chart.draw_series(std::iter::once(PathElement::new(
                xy(&p.measured),
                MEASURED.stroke_width(1),
            )))?;
            chart.draw_series(std::iter::once(PathElement::new(
                xy(&p.predicted),
                PREDICTED.stroke_width(1),
            )))?;
        }
        root.present()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_polyline_per_curve_and_the_same_bytes_twice() {
        let xs: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let panels: Vec<Panel> = (0..3)
            .map(|j| Panel {
                name: format!("j{j}"),
                measured: xs.iter().map(|x| (x + j as f64).sin()).collect(),
                predicted: xs.iter().map(|x| (x + j as f64).sin() + 0.01).collect(),
            })
            .collect();
        let plot = EffortPlot {
            title: "t",
            x_label: "t (s)",
            xs: &xs,
            panels: &panels,
        };
        let a = plot.svg().unwrap();
        assert_eq!(a, plot.svg().unwrap());
        let curves = |c: RGBColor| {
            let stroke = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
            a.lines()
                .filter(|l| l.starts_with("<polyline") && l.contains(&stroke))
                .count()
        };
        assert_eq!((curves(MEASURED), curves(PREDICTED)), (3, 3));
        assert!(a.contains("j2: residual RMS 1.0000e-2"));
        assert!((panels[0].residual_rms() - 0.01).abs() < 1e-12);
    }
}
