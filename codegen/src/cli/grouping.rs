//! The grouping matrix `G` of a mechanism's base parameters over its named standard
//! parameters, `π_base = G π_standard` (docs/identification.md): what the identification tools
//! use to compare a model's base parameters with the estimates, for every kind.

use std::collections::HashMap;

/// `G`, with the standard parameters' names its columns follow.
pub struct Grouping {
    /// The standard parameters' names (`XX_link2`, `FV_j1`, …), in the regressor's order.
    pub standard_names: Vec<String>,
    /// `NBP` rows of `standard_names.len()` entries.
    pub rows: Vec<Vec<f64>>,
}

impl Grouping {
    /// From the base parameters' groups (`(standard index, coefficient)` per base parameter).
    pub fn new(groups: &[Vec<(usize, f64)>], standard_names: Vec<String>) -> Grouping {
        let n = standard_names.len();
        let rows = groups
            .iter()
            .map(|gr| {
                let mut row = vec![0.0; n];
                for &(k, c) in gr {
                    row[k] += c;
                }
                row
            })
            .collect();
        Grouping {
            standard_names,
            rows,
        }
    }

    /// `G · π` with `π` read by name from `values` (a name it lacks counts 0).
    pub fn apply(&self, values: &HashMap<String, f64>) -> Vec<f64> {
        let x: Vec<f64> = self
            .standard_names
            .iter()
            .map(|n| values.get(n).copied().unwrap_or(0.0))
            .collect();
        self.rows
            .iter()
            .map(|row| row.iter().zip(&x).map(|(a, b)| a * b).sum())
            .collect()
    }
}
