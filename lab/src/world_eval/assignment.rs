//! The identity score's one-to-one assignment of reported ids to pieces (IDF1's IDTP): the
//! optimal matching by total weight.

/// Optimal one-to-one assignment maximising total weight (Hungarian, via `pathfinding`).
pub fn max_assignment(w: &[Vec<i64>]) -> i64 {
    let rows = w.len();
    let cols = w.iter().map(Vec::len).max().unwrap_or(0);
    let n = rows.max(cols);
    if n == 0 {
        return 0;
    }
    let mut m = pathfinding::matrix::Matrix::new(n, n, 0i64);
    for (i, r) in w.iter().enumerate() {
        for (j, &x) in r.iter().enumerate() {
            m[(i, j)] = x;
        }
    }
    pathfinding::kuhn_munkres::kuhn_munkres(&m).0
}
