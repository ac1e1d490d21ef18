//! The measurement file of `identify` (docs/identification.md, "The CSV format"): a header
//! naming the columns, then one row per sample. Columns per joint `i` (1-based) or by the
//! joint's name: `q<i>` / `q_<joint>`, `qd<i>` / `qd_<joint>`, `qdd<i>` / `qdd_<joint>`,
//! `tau<i>` / `tau_<joint>`; `t` (s) optional. With `t`, `q` and `tau` but no `qd`/`qdd`, the
//! positions are filtered and differentiated ([`super::filter`]). Lines that start with `#`
//! and blank lines are skipped; other columns are ignored. Every problem is an error at its
//! file, line and column.

use super::filter::{differentiate, filtfilt};

/// Measured samples, one entry per kept row.
#[derive(Clone, Debug, Default)]
pub struct Samples {
    /// Joint positions.
    pub q: Vec<Vec<f64>>,
    /// Joint velocities.
    pub qd: Vec<Vec<f64>>,
    /// Joint accelerations.
    pub qdd: Vec<Vec<f64>>,
    /// Joint efforts.
    pub tau: Vec<Vec<f64>>,
    /// What was done to the data (filtering), for the report.
    pub note: Option<String>,
    /// The file's line (1-based) of each kept row.
    pub lines: Vec<usize>,
    /// The `t` column of each kept row, s (empty without one).
    pub t: Vec<f64>,
}

/// How positions-only data are filtered.
#[derive(Clone, Copy, Debug)]
pub struct Filtering {
    /// Cutoff of the zero-phase low-pass, Hz.
    pub cutoff: f64,
}

/// The columns a mechanism's file has: positions, speeds, accelerations and efforts.
#[derive(Clone, Debug)]
pub struct Columns {
    /// The prefixes of the four kinds: `q, qd, qdd, tau` (trees) or `x, u, ud, tau`
    /// (platforms).
    pub kinds: [&'static str; 4],
    /// How many columns of each kind.
    pub counts: [usize; 4],
    /// Per kind, the names `kind_<name>` may use in place of `kind<i>` (empty: none).
    pub names: [Vec<String>; 4],
    /// Whether positions-only data (`t`, positions, efforts) can be filtered and
    /// differentiated (the speeds are the positions' rates).
    pub differentiable: bool,
}

impl Columns {
    /// A tree's: `q, qd, qdd, tau` per joint, or by the joint's name.
    pub fn joints(joints: &[String]) -> Columns {
        let n = joints.len();
        Columns {
            kinds: ["q", "qd", "qdd", "tau"],
            counts: [n; 4],
            names: std::array::from_fn(|_| joints.to_vec()),
            differentiable: true,
        }
    }
}

/// Where column `kind` number `i` is, if anywhere: `kind{i+1}` or `kind_{name}`.
fn find(header: &[String], kind: &str, i: usize, name: Option<&String>) -> Option<usize> {
    let a = format!("{kind}{}", i + 1);
    let b = name.map(|n| format!("{kind}_{n}"));
    header
        .iter()
        .position(|h| *h == a || b.as_ref().is_some_and(|b| h == b))
}

/// Read `text` (the file `file`) with columns `columns`, needing at least `min_rows` samples
/// after filtering.
pub fn read(
    file: &str,
    text: &str,
    columns: &Columns,
    min_rows: usize,
    filtering: Filtering,
) -> Result<Samples, String> {
    let kinds = columns.kinds;
    let n = columns.counts[3];
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(format!(
            "error: {file}: empty: expected a header line (t, {}1.., {}1.., {}1.., {}1..)",
            kinds[0], kinds[1], kinds[2], kinds[3]
        ));
    };
    let header: Vec<String> = header.split(',').map(|h| h.trim().to_string()).collect();
    for (c, h) in header.iter().enumerate() {
        if header[..c].contains(h) {
            return Err(format!(
                "error: {file}:{}:{}: column `{h}` appears twice",
                hline + 1,
                c + 1
            ));
        }
    }
    let mut cols: Vec<Vec<Option<usize>>> = Vec::new();
    for (k, kind) in kinds.iter().enumerate() {
        cols.push(
            (0..columns.counts[k])
                .map(|i| find(&header, kind, i, columns.names[k].get(i)))
                .collect(),
        );
    }
    let t_col = header.iter().position(|h| h == "t");
    let has = |k: usize| cols[k].iter().all(Option::is_some);
    let none = |k: usize| cols[k].iter().all(Option::is_none);
    let positions_only = columns.differentiable && has(0) && has(3) && none(1) && none(2);
    if positions_only && t_col.is_none() {
        return Err(format!(
            "error: {file}:{}: only `{}` and `{}` columns: a `t` column is needed to differentiate the positions",
            hline + 1,
            kinds[0],
            kinds[3]
        ));
    }
    if !positions_only {
        let cols = &cols;
        let missing: Vec<String> = kinds
            .iter()
            .enumerate()
            .flat_map(|(k, kind)| {
                cols[k]
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.is_none())
                    .map(move |(i, _)| format!("{kind}{}", i + 1))
            })
            .collect();
        if !missing.is_empty() {
            let expected: Vec<String> = kinds
                .iter()
                .zip(columns.counts)
                .map(|(k, c)| format!("{k}1..{k}{c}"))
                .collect();
            let alternatives = if columns.differentiable {
                format!(
                    ", or {}_<joint> … by joint name; or t, {} and {} only, to filter and differentiate",
                    kinds[0], kinds[0], kinds[3]
                )
            } else {
                format!(", or {}_<actuated joint>", kinds[3])
            };
            return Err(format!(
                "error: {file}:{}: missing column{} {} (expected t (optional), {}{alternatives})",
                hline + 1,
                if missing.len() == 1 { "" } else { "s" },
                missing.join(", "),
                expected.join(", ")
            ));
        }
    }
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut line_of = Vec::new();
    for (ln, line) in lines {
        line_of.push(ln + 1);
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            return Err(format!(
                "error: {file}:{}: {} fields, the header has {}",
                ln + 1,
                fields.len(),
                header.len()
            ));
        }
        let mut row = Vec::with_capacity(fields.len());
        for (c, f) in fields.iter().enumerate() {
            let v = f.trim().parse::<f64>().map_err(|_| {
                format!(
                    "error: {file}:{}:{}: column `{}`: `{}` is not a number",
                    ln + 1,
                    c + 1,
                    header[c],
                    f.trim()
                )
            })?;
            if !v.is_finite() {
                return Err(format!(
                    "error: {file}:{}:{}: column `{}`: `{}` is not finite",
                    ln + 1,
                    c + 1,
                    header[c],
                    f.trim()
                ));
            }
            row.push(v);
        }
        rows.push(row);
    }
    let pick = |k: usize, r: &[f64]| -> Vec<f64> {
        cols[k].iter().map(|c| c.map_or(0.0, |c| r[c])).collect()
    };
    let mut s = Samples::default();
    if positions_only {
        let t: Vec<f64> = rows.iter().map(|r| r[t_col.unwrap_or(0)]).collect();
        let dt = uniform_step(file, &t)?;
        let fs = 1.0 / dt;
        if !(filtering.cutoff > 0.0 && filtering.cutoff < 0.5 * fs) {
            return Err(format!(
                "error: --cutoff {} Hz: must be in (0, {}) (half the sample rate of {file})",
                filtering.cutoff,
                0.5 * fs
            ));
        }
        // Dropped at each end: the filter's transient (about one cutoff period) and the ends of
        // the differences.
        let edge = ((fs / filtering.cutoff).ceil() as usize).max(2);
        if rows.len() < 2 * edge + min_rows {
            return Err(format!(
                "error: {file}: {} rows: too few to filter and differentiate (need {} samples after dropping {edge} at each end)",
                rows.len(),
                min_rows
            ));
        }
        let mut q_cols = vec![Vec::new(); n];
        let mut qd_cols = vec![Vec::new(); n];
        let mut qdd_cols = vec![Vec::new(); n];
        let mut tau_cols = vec![Vec::new(); n];
        for i in 0..n {
            let mut q: Vec<f64> = rows.iter().map(|r| pick(0, r)[i]).collect();
            let mut tau: Vec<f64> = rows.iter().map(|r| pick(3, r)[i]).collect();
            filtfilt(&mut q, filtering.cutoff, fs);
            filtfilt(&mut tau, filtering.cutoff, fs);
            let (d, dd) = differentiate(&q, dt);
            q_cols[i] = q;
            qd_cols[i] = d;
            qdd_cols[i] = dd;
            tau_cols[i] = tau;
        }
        for k in edge..rows.len() - edge {
            s.q.push((0..n).map(|i| q_cols[i][k]).collect());
            s.qd.push((0..n).map(|i| qd_cols[i][k]).collect());
            s.qdd.push((0..n).map(|i| qdd_cols[i][k]).collect());
            s.tau.push((0..n).map(|i| tau_cols[i][k]).collect());
            s.lines.push(line_of[k]);
            s.t.push(t[k]);
        }
        s.note = Some(format!(
            "positions only: q and tau low-passed (2nd-order Butterworth forward and backward, cutoff {} Hz at {:.6} Hz sampling), qd and qdd by central differences; {edge} samples dropped at each end",
            filtering.cutoff, fs
        ));
    } else {
        if rows.len() < min_rows {
            return Err(format!(
                "error: {file}: {} rows: too few (the regressor needs at least {min_rows} samples)",
                rows.len()
            ));
        }
        s.lines = line_of;
        for r in &rows {
            if let Some(c) = t_col {
                s.t.push(r[c]);
            }
            s.q.push(pick(0, r));
            s.qd.push(pick(1, r));
            s.qdd.push(pick(2, r));
            s.tau.push(pick(3, r));
        }
    }
    Ok(s)
}

/// The sampling step of `t`, which must increase uniformly (within 1e-6 of the mean step).
fn uniform_step(file: &str, t: &[f64]) -> Result<f64, String> {
    if t.len() < 3 {
        return Err(format!("error: {file}: too few rows to differentiate"));
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if dt.is_nan() || dt <= 0.0 {
        return Err(format!("error: {file}: column `t` does not increase"));
    }
    for (k, w) in t.windows(2).enumerate() {
        if ((w[1] - w[0]) - dt).abs() > 1e-6 * dt {
            return Err(format!(
                "error: {file}: column `t`: the step between samples {} and {} is {} s, not the mean {dt} s (positions-only data must be sampled uniformly)",
                k + 1,
                k + 2,
                w[1] - w[0]
            ));
        }
    }
    Ok(dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints() -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    const F: Filtering = Filtering { cutoff: 5.0 };

    #[test]
    fn columns_by_index_or_joint_name_in_any_order() {
        // A byte-order mark and CRLF line ends are read as well.
        let text = "\u{feff}tau2,q1,q_b,qd1,qd2,qdd1,qdd_b,tau_a,extra\r\n1,2,3,4,5,6,7,8,9\r\n";
        let s = read("d.csv", text, &Columns::joints(&joints()), 1, F).unwrap();
        assert_eq!(s.q, vec![vec![2.0, 3.0]]);
        assert_eq!(s.qd, vec![vec![4.0, 5.0]]);
        assert_eq!(s.qdd, vec![vec![6.0, 7.0]]);
        assert_eq!(s.tau, vec![vec![8.0, 1.0]]);
    }

    #[test]
    fn bad_files_are_errors_at_their_place() {
        let h = "t,q1,q2,qd1,qd2,qdd1,qdd2,tau1,tau2\n";
        let e = |t: &str| read("d.csv", t, &Columns::joints(&joints()), 1, F).unwrap_err();
        assert!(e("").contains("empty"));
        assert!(e("q1,q2\n").contains("missing columns qd1, qd2"));
        assert!(e(&format!("{h}0,1,2,3,4,5,6,7\n")).contains("d.csv:2: 8 fields"));
        assert!(e(&format!("{h}0,1,2,3,x,5,6,7,8\n")).contains("d.csv:2:5: column `qd2`"));
        assert!(e(&format!("{h}# c\n0,1,2,3,4,NaN,6,7,8\n")).contains("d.csv:3:6"));
        assert!(e(h).contains("too few"));
        assert!(e("t,q1,q1\n").contains("twice"));
        assert!(e("q1,q2,tau1,tau2\n1,2,3,4\n").contains("`t` column is needed"));
    }
}
