//! The measurement file of `identify` (docs/identification.md, "The CSV format"): a header
//! naming the columns, then one row per sample. Columns per joint `i` (1-based) or by the
//! joint's name: `q<i>` / `q_<joint>`, `qd<i>` / `qd_<joint>`, `qdd<i>` / `qdd_<joint>`,
//! `tau<i>` / `tau_<joint>`; `t` (s) optional. With `t`, `q` and `tau` but no `qd`/`qdd`, the
//! positions are filtered and differentiated ([`super::filter`]). Lines that start with `#`
//! and blank lines are skipped; other columns are ignored. Every problem is an error at its
//! file, line and column.

use codegen::spec::MAX_MAGNITUDE;

use super::filter::{differentiate, filtfilt, settling};

/// Cutoff periods of samples dropped at each end of positions-only data (the filter's
/// transient; see [`read`]).
const EDGE_PERIODS: f64 = 3.0;
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
    /// Positions-only data: `(cutoff, sample rate)` (Hz) of the low-pass that the efforts
    /// (here raw) and the regressor's columns go through together (parallel filtering: the
    /// caller filters both over the kept rows, so that the same linear filter meets `τ = Y π`
    /// on both sides).
    pub parallel: Option<(f64, f64)>,
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

/// Where column `kind` number `i` is, if anywhere: `kind{i+1}` or `kind_{name}`; `Err` (the
/// two columns) when the header has both.
fn find(
    header: &[String],
    kind: &str,
    i: usize,
    name: Option<&String>,
) -> Result<Option<usize>, (usize, usize)> {
    let a = format!("{kind}{}", i + 1);
    let b = name.map(|n| format!("{kind}_{n}"));
    let mut at = header
        .iter()
        .enumerate()
        .filter(|(_, h)| **h == a || b.as_ref().is_some_and(|b| *h == b))
        .map(|(c, _)| c);
    match (at.next(), at.next()) {
        (Some(x), Some(y)) => Err((x, y)),
        (x, _) => Ok(x),
    }
}

/// `n` and the noun, plural unless `n` is 1.
fn count(n: usize, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
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
    // A set, not a scan of the columns before: a header of 200,000 columns took minutes.
    let mut seen = std::collections::HashSet::new();
    for (c, h) in header.iter().enumerate() {
        // Unnamed columns (a trailing comma) are ignored like any other unknown one.
        if !h.is_empty() && !seen.insert(h.as_str()) {
            return Err(format!(
                "error: {file}:{}:{}: column `{h}` appears twice",
                hline + 1,
                c + 1
            ));
        }
    }
    let mut cols: Vec<Vec<Option<usize>>> = Vec::new();
    for (k, kind) in kinds.iter().enumerate() {
        let mut of_kind = Vec::new();
        for i in 0..columns.counts[k] {
            let name = columns.names[k].get(i);
            match find(&header, kind, i, name) {
                Ok(c) => of_kind.push(c),
                Err((a, b)) => {
                    return Err(format!(
                        "error: {file}:{}:{}: columns `{}` (column {}) and `{}` both give {kind}{}{}: keep one",
                        hline + 1,
                        b + 1,
                        header[a],
                        a + 1,
                        header[b],
                        i + 1,
                        name.map_or(String::new(), |n| format!(" (joint `{n}`)"))
                    ));
                }
            }
        }
        cols.push(of_kind);
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
                .map(|(k, c)| {
                    if c == 1 {
                        format!("{k}1")
                    } else {
                        format!("{k}1..{k}{c}")
                    }
                })
                .collect();
            let alternatives = if columns.differentiable && columns.names[0].is_empty() {
                format!(
                    ", or {}_<actuated joint>; or t, {} and {} only, to filter and differentiate",
                    kinds[3], kinds[0], kinds[3]
                )
            } else if columns.differentiable {
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
    // Only the columns read are parsed: the others ("other columns are ignored") may hold
    // anything, labels or nothing.
    let mut used = vec![false; header.len()];
    for c in cols.iter().flatten().flatten().chain(t_col.as_ref()) {
        used[*c] = true;
    }
    let mut position = vec![false; header.len()];
    for c in cols[0].iter().flatten() {
        position[*c] = true;
    }
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut line_of = Vec::new();
    for (ln, line) in lines {
        line_of.push(ln + 1);
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            return Err(format!(
                "error: {file}:{}:{}: {}, the header has {}",
                ln + 1,
                fields.len().min(header.len()) + 1,
                count(fields.len(), "field"),
                header.len()
            ));
        }
        let mut row = vec![0.0; fields.len()];
        for (c, f) in fields.iter().enumerate().filter(|(c, _)| used[*c]) {
            let cell = f.trim();
            let v = cell.parse::<f64>().map_err(|_| {
                format!(
                    "error: {file}:{}:{}: column `{}`: `{}` is not a number",
                    ln + 1,
                    c + 1,
                    header[c],
                    cell.escape_debug()
                )
            })?;
            if !v.is_finite() {
                return Err(format!(
                    "error: {file}:{}:{}: column `{}`: `{cell}` is not finite",
                    ln + 1,
                    c + 1,
                    header[c],
                ));
            }
            // A position past the spec's own bound on numbers is no measurement: an angle of
            // 1e308 rad fitted without complaint, and beyond 2⁵³ a double cannot even tell
            // one turn from the next.
            if position[c] && v.abs() > MAX_MAGNITUDE {
                return Err(format!(
                    "error: {file}:{}:{}: column `{}`: `{cell}` is beyond {:e} (a position in rad or m; check the column's unit)",
                    ln + 1,
                    c + 1,
                    header[c],
                    MAX_MAGNITUDE,
                ));
            }
            row[c] = v;
        }
        rows.push(row);
    }
    let pick = |k: usize, r: &[f64]| -> Vec<f64> {
        cols[k].iter().map(|c| c.map_or(0.0, |c| r[c])).collect()
    };
    let mut s = Samples::default();
    if positions_only {
        let t: Vec<f64> = rows.iter().map(|r| r[t_col.unwrap_or(0)]).collect();
        let dt = uniform_step(file, &t, t_col.unwrap_or(0), &line_of)?;
        let fs = 1.0 / dt;
        if !(filtering.cutoff > 0.0 && filtering.cutoff < 0.5 * fs) {
            return Err(format!(
                "error: --cutoff {:?} Hz: must be in (0, {:?}) (half the sample rate of {file})",
                filtering.cutoff,
                0.5 * fs
            ));
        }
        // Dropped at each end: the filter's transient and the ends of the differences. The
        // odd extension continues value and slope but flips the curvature, a step of `2 q̈₀`
        // in `q̈` at the seam, whose response decays as `exp(−ζ ω_c t)` (`ζ = 1/√2`):
        // `exp(−2π/√2) = 1.2e-2` of it after one cutoff period, `1.6e-6` after three, the
        // in-band error's level (docs/identification.md, "The CSV format"). Compared as a
        // float first: a cutoff far below the sample rate makes it larger than any file.
        let edge = settling(filtering.cutoff, fs, EDGE_PERIODS).ceil().max(2.0);
        if 2.0 * edge + min_rows as f64 > rows.len() as f64 {
            return Err(format!(
                "error: {file}: {}: too few to filter and differentiate at --cutoff {:?} Hz (need {min_rows} samples after dropping {} at each end: the filter's settling, three cutoff periods or more near half the sample rate)",
                count(rows.len(), "row"),
                filtering.cutoff,
                if edge < 1e12 {
                    format!("{edge:.0}")
                } else {
                    format!("{edge:.3e}")
                },
            ));
        }
        let edge = edge as usize;
        // A platform has more positions (`x`, a quaternion's four) than efforts: `qd` and
        // `qdd` are then the rates of every position, which the caller turns into speeds.
        let nq = columns.counts[0];
        let mut q_cols = vec![Vec::new(); nq];
        let mut qd_cols = vec![Vec::new(); nq];
        let mut qdd_cols = vec![Vec::new(); nq];
        let mut tau_cols = vec![Vec::new(); n];
        for i in 0..nq {
            let mut q: Vec<f64> = rows.iter().map(|r| pick(0, r)[i]).collect();
            filtfilt(&mut q, filtering.cutoff, fs);
            let (d, dd) = differentiate(&q, dt);
            q_cols[i] = q;
            qd_cols[i] = d;
            qdd_cols[i] = dd;
        }
        // The efforts stay raw here: the caller filters them with the regressor's columns.
        for (i, col) in tau_cols.iter_mut().enumerate() {
            *col = rows.iter().map(|r| pick(3, r)[i]).collect();
        }
        s.parallel = Some((filtering.cutoff, fs));
        for k in edge..rows.len() - edge {
            s.q.push((0..nq).map(|i| q_cols[i][k]).collect());
            s.qd.push((0..nq).map(|i| qd_cols[i][k]).collect());
            s.qdd.push((0..nq).map(|i| qdd_cols[i][k]).collect());
            s.tau.push((0..n).map(|i| tau_cols[i][k]).collect());
            s.lines.push(line_of[k]);
            s.t.push(t[k]);
        }
        s.note = Some(format!(
            "positions only: {} and {} low-passed (2nd-order Butterworth forward and backward, cutoff {} Hz at {:.6} Hz sampling; tau with the regressor's columns, parallel filtering), {} and {} by central differences; {edge} samples dropped at each end",
            kinds[0],
            kinds[3],
            filtering.cutoff,
            fs,
            if kinds[0] == "x" { "their rates" } else { "qd" },
            if kinds[0] == "x" {
                "second rates"
            } else {
                "qdd"
            },
        ));
    } else {
        if rows.len() < min_rows {
            return Err(format!(
                "error: {file}: {}: too few (the regressor needs at least {min_rows} samples)",
                count(rows.len(), "row")
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

/// The sampling step of `t` (column `col`, 0-based; `lines`: the file line of each sample),
/// which must increase uniformly (within 1e-6 of the mean step).
fn uniform_step(file: &str, t: &[f64], col: usize, lines: &[usize]) -> Result<f64, String> {
    if t.len() < 3 {
        return Err(format!(
            "error: {file}: {}: too few to differentiate",
            count(t.len(), "row")
        ));
    }
    let at = |k: usize| format!("{file}:{}:{}", lines[k], col + 1);
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(format!(
            "error: {}: column `t`: {} s after {} s: time must increase (positions-only data are differentiated in time)",
            at(k + 1),
            t[k + 1],
            t[k]
        ));
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if !(dt > 0.0 && dt.is_finite() && (1.0 / dt).is_finite()) {
        return Err(format!(
            "error: {}: column `t`: a mean step of {dt:e} s cannot be differentiated over",
            at(t.len() - 1)
        ));
    }
    for (k, w) in t.windows(2).enumerate() {
        if ((w[1] - w[0]) - dt).abs() > 1e-6 * dt {
            return Err(format!(
                "error: {}: column `t`: the step from the row before is {} s, not the mean {dt} s (positions-only data must be sampled uniformly)",
                at(k + 1),
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
        assert!(e(&format!("{h}0,1,2,3,4,5,6,7\n")).contains("d.csv:2:9: 8 fields"));
        assert!(e(&format!("{h}0,1,2,3,x,5,6,7,8\n")).contains("d.csv:2:5: column `qd2`"));
        assert!(e(&format!("{h}# c\n0,1,2,3,4,NaN,6,7,8\n")).contains("d.csv:3:6"));
        // Positions past the spec's bound on numbers (1e9); speeds and efforts are judged by
        // the regressor's reach instead.
        assert!(e(&format!("{h}0,1,1e308,3,4,5,6,7,8\n")).contains("d.csv:2:3: column `q2`"));
        assert!(e(&format!("{h}0,-2e9,2,3,4,5,6,7,8\n")).contains("is beyond 1e9"));
        let speed = read(
            "d.csv",
            &format!("{h}0,1e9,2,2e9,4,5,6,7,8\n"),
            &Columns::joints(&joints()),
            1,
            F,
        );
        assert_eq!(speed.unwrap().qd, vec![vec![2e9, 4.0]]);
        assert!(e(h).contains("too few"));
        assert!(e("t,q1,q1\n").contains("twice"));
        assert!(e("q1,q2,tau1,tau2\n1,2,3,4\n").contains("`t` column is needed"));
    }
}
