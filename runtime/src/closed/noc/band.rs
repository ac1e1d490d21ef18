//! The banded order of `Φ_d`'s columns (reverse Cuthill–McKee) and rows, so that a chain of
//! loops factorizes in `O(n)`.

use alloc::vec;
use alloc::vec::Vec;

use super::plan::{Plan, Row, row_cut};

/// Order the dependent coordinates (the columns of `Φ_d`) and the loop equations (its rows)
/// for a narrow band: a chain of loops (the N-four-bar, a ladder) written in any order then
/// factorizes in `O(n)` instead of `O(n³)`, since the generated LU's pivot selects only mix
/// rows that share a column. Columns by reverse Cuthill–McKee over "appear in the same
/// equation" (structurally: the joints that move either body of the equation's cut), rows by
/// their first and last column; the spec's order stays where this does not make the LU
/// cheaper (counted on the structural pattern) and for fewer than eight dependent coordinates.
pub(super) fn band_order(plan: &mut Plan) {
    // Below this many dependent coordinates the dense LU costs a few dozen selects at most:
    // the spec's order stays (and with it the rounding of the bundled small loops).
    const BAND_MIN: usize = 8;
    let nd = plan.dependent.len();
    let col_of = |j: usize| plan.dependent.iter().position(|&d| d == j);
    let pattern = |r: &Row| -> Vec<usize> {
        let c = &plan.cuts[row_cut(r)];
        let moves = |b: Option<usize>, j: usize| b.is_some_and(|b| plan.anc[b][j]);
        (0..plan.joints.len())
            .filter(|&j| moves(c.parent, j) || moves(c.child, j))
            .filter_map(col_of)
            .collect()
    };
    let rows: Vec<Vec<usize>> = plan.rows.iter().chain(&plan.spare).map(pattern).collect();
    let mut adj = vec![Vec::<usize>::new(); nd];
    for r in &rows {
        for &a in r {
            for &b in r {
                if a != b && !adj[a].contains(&b) {
                    adj[a].push(b);
                }
            }
        }
    }
    let mut order: Vec<usize> = Vec::with_capacity(nd);
    let mut seen = vec![false; nd];
    while order.len() < nd {
        let start = (0..nd)
            .filter(|&c| !seen[c])
            .min_by_key(|&c| (adj[c].len(), c))
            .unwrap_or(0);
        seen[start] = true;
        let mut head = order.len();
        order.push(start);
        while head < order.len() {
            let mut next: Vec<usize> = adj[order[head]]
                .iter()
                .copied()
                .filter(|&c| !seen[c])
                .collect();
            next.sort_by_key(|&c| (adj[c].len(), c));
            for c in next {
                seen[c] = true;
                order.push(c);
            }
            head += 1;
        }
    }
    order.reverse();
    // The cost of the LU (as the generator sees it) in a column order: the entries that the
    // swap selects and the eliminations touch, on the structural pattern. Rows in the order
    // they get below.
    let lu_cost = |pos: &[usize]| -> usize {
        let mut m: Vec<Vec<bool>> = rows
            .iter()
            .map(|r| {
                let mut row = vec![false; nd];
                for &c in r {
                    row[pos[c]] = true;
                }
                row
            })
            .collect();
        m.sort_by_key(|r| (r.iter().position(|&v| v), r.iter().rposition(|&v| v)));
        let mut cost = 0;
        for k in 0..nd.min(m.len()) {
            for i in k + 1..m.len() {
                if m[i][k] {
                    for j in k..nd {
                        let v = m[i][j] || m[k][j];
                        cost += usize::from(v);
                        m[i][j] = v;
                        m[k][j] = v;
                    }
                }
            }
            for i in k + 1..m.len() {
                if m[i][k] {
                    for j in k + 1..nd {
                        cost += usize::from(m[k][j]);
                        m[i][j] |= m[k][j];
                    }
                }
            }
        }
        cost
    };
    let mut pos = vec![0; nd];
    for (p, &c) in order.iter().enumerate() {
        pos[c] = p;
    }
    let identity: Vec<usize> = (0..nd).collect();
    if nd < BAND_MIN || lu_cost(&pos) >= lu_cost(&identity) {
        pos = identity;
    }
    let mut dependent = plan.dependent.clone();
    for (c, &p) in pos.iter().enumerate() {
        dependent[p] = plan.dependent[c];
    }
    let key = |r: &Row| {
        let cols = pattern(r);
        (
            cols.iter().map(|&c| pos[c]).min().unwrap_or(usize::MAX),
            cols.iter().map(|&c| pos[c]).max().unwrap_or(0),
        )
    };
    let mut kept = plan.rows.clone();
    kept.sort_by_key(|r| key(r));
    let mut spare = plan.spare.clone();
    spare.sort_by_key(|r| key(r));
    plan.rows = kept;
    plan.spare = spare;
    plan.dependent = dependent;
}
