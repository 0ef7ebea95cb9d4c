//! Adaptive DBSCAN over the global cloud: grid-indexed, O(n) on average, allocation-free.
//!
//! # The ε rule
//!
//! Each point gets its own radius from the density around it. The plane is cut into square
//! cells of side `c = ε_min / √2` (0.057 m; larger if the cloud is too wide for
//! [`GRID_CELLS`]); `n` is the number of points in the 5 × 5 cells around the point's cell, a
//! box of side `L = 5c` (0.28 m). LiDAR points lie on curves (wall lines, the arcs of legs), so
//! the block holds a line of length about `L` and the spacing along it is `s = L / n`. A point
//! on a line with spacing `s` has `2ε / s` neighbours within ε; `min_samples` of them need
//! `ε ≥ min_samples · s / 2`. The rule takes twice that, for margin against gaps:
//!
//! ```text
//! ε_i = clamp(min_samples · L / n_i, ε_min, ε_max)        (0.08 m, 0.32 m by default)
//! ```
//!
//! Why: a wall seen from far away, or only on a few revolutions, is sampled sparsely, and a
//! fixed small ε cuts it into fragments that then look like objects; a fixed large ε joins a
//! box or a desk leg to the wall 0.15 m behind it wherever the cloud is dense. Dense regions
//! therefore get ε_min and sparse ones up to ε_max. (The study's code computed one ε for the
//! whole cloud, `clip(0.15 · (1 + 2 · mean nearest-neighbour distance), 0.08, 0.32)`, which in a
//! cloud of thousands of points is ≈ 0.15 m everywhere.)
//!
//! # DBSCAN with per-point ε
//!
//! `j` is a neighbour of `i` when `|p_i − p_j| ≤ min(ε_i, ε_j)` (the point itself counts, as
//! in scikit-learn): two points are judged at the finer of their two scales, so the relation
//! is symmetric and a sparse point's wide ε cannot reach into a dense object (the thin wall
//! edge beside a box's shadow would otherwise bridge the 0.15 m to the box). `i` is a core point with at least `min_samples` neighbours. Core points are
//! joined (union–find) with every core point in their neighbourhood; a border point joins the
//! first core point, in cell order, that has it as a neighbour; the rest is noise. Clusters
//! with fewer than `min_cluster_points` points are dropped (counted as noise). With one ε for
//! every point this is exactly DBSCAN.
//!
//! # Cost and capacities
//!
//! Points are bucketed by a counting sort into cells (no hashing). Any two points of one cell
//! are within ε_min, so a cell holding `min_samples` points is all core points in one set
//! without a distance computed (the grid DBSCAN of Gunawan, 2013). Two cells' sets are joined
//! at the first core pair within reach, and a pair of cells already in one set is skipped, so
//! a dense wall costs one union per neighbouring cell instead of a scan per point. Sparse cells
//! count neighbours point by point over `(2⌈ε_i / c⌉ + 1)²` cells. At most [`MAX_CLUSTERS`]
//! clusters are kept (in cell order); more are counted in
//! [`DbscanStats::clusters_over_capacity`].

use crate::cloud::CLOUD_CAPACITY;
use crate::geometry::Point2;

/// Grid cells at most (256 × 256 cells of 0.057 m cover 14.5 m square; wider clouds get
/// larger cells, which is slower but still exact).
pub const GRID_CELLS: usize = 65_536;
/// Clusters kept at most per run.
pub const MAX_CLUSTERS: usize = 128;

/// Points farther than this from the map origin (metres) are refused as corrupt: no robot
/// maps 10 km, and the bound keeps the grid arithmetic finite.
pub const COORD_LIMIT_M: f32 = 1.0e4;

/// Label of a point in no cluster.
pub const NOISE: u16 = u16::MAX;

/// DBSCAN settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DbscanConfig {
    /// Smallest ε, metres (the grid cell side is ε_min / √2).
    pub eps_min_m: f32,
    /// Largest ε, metres.
    pub eps_max_m: f32,
    /// Neighbours (self included) that make a core point.
    pub min_samples: u16,
    /// Clusters with fewer points are dropped.
    pub min_cluster_points: u16,
}

impl Default for DbscanConfig {
    fn default() -> Self {
        DbscanConfig {
            eps_min_m: 0.08,
            eps_max_m: 0.32,
            min_samples: 10,
            min_cluster_points: 20,
        }
    }
}

/// A cluster: a run of [`Dbscan::points`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cluster {
    /// First point.
    pub start: u16,
    /// Number of points.
    pub len: u16,
}

impl Cluster {
    /// The index range in [`Dbscan::points`].
    pub fn range(&self) -> core::ops::Range<usize> {
        self.start as usize..self.start as usize + self.len as usize
    }
}

/// What one run found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DbscanStats {
    /// Points clustered.
    pub points: u32,
    /// Points in no kept cluster (noise, or in clusters below the minimum size).
    pub noise: u32,
    /// Clusters below `min_cluster_points`.
    pub small_clusters: u32,
    /// Clusters beyond [`MAX_CLUSTERS`] (their points are counted as noise).
    pub clusters_over_capacity: u32,
    /// Grid cell side used, metres.
    pub cell_m: f32,
    /// Points not finite, refused.
    pub rejected: u32,
}

/// DBSCAN state: every buffer it needs, allocated once.
#[derive(Clone)]
pub struct Dbscan {
    /// Input points bucketed by cell; after a run, grouped by cluster (clusters first).
    sorted: [Point2; CLOUD_CAPACITY],
    /// Output: cluster points, contiguous per cluster.
    out: [Point2; CLOUD_CAPACITY],
    eps: [f32; CLOUD_CAPACITY],
    /// Union–find parent (core points), owner (border points) or `NOISE`.
    parent: [u16; CLOUD_CAPACITY],
    core: [bool; CLOUD_CAPACITY],
    cell_start: [u16; GRID_CELLS + 1],
    /// Cluster id per union–find root, then per point.
    label: [u16; CLOUD_CAPACITY],
    clusters: [Cluster; MAX_CLUSTERS],
    n_clusters: usize,
    stats: DbscanStats,
}

impl Default for Dbscan {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for Dbscan {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Dbscan")
            .field("clusters", &self.n_clusters)
            .field("stats", &self.stats)
            .finish()
    }
}

#[derive(Clone, Copy)]
struct Grid {
    origin: Point2,
    cell: f32,
    nx: usize,
    ny: usize,
}

impl Grid {
    fn cell_xy(&self, p: Point2) -> (usize, usize) {
        let cx = ((p.x - self.origin.x) / self.cell) as usize;
        let cy = ((p.y - self.origin.y) / self.cell) as usize;
        (cx.min(self.nx - 1), cy.min(self.ny - 1))
    }
    fn index(&self, p: Point2) -> usize {
        let (cx, cy) = self.cell_xy(p);
        cy * self.nx + cx
    }
}

fn find(parent: &mut [u16], mut i: usize) -> usize {
    while parent[i] as usize != i {
        let g = parent[parent[i] as usize];
        parent[i] = g;
        i = g as usize;
    }
    i
}

impl Dbscan {
    /// Empty state.
    pub const fn new() -> Self {
        Dbscan {
            sorted: [Point2::new(0.0, 0.0); CLOUD_CAPACITY],
            out: [Point2::new(0.0, 0.0); CLOUD_CAPACITY],
            eps: [0.0; CLOUD_CAPACITY],
            parent: [0; CLOUD_CAPACITY],
            core: [false; CLOUD_CAPACITY],
            cell_start: [0; GRID_CELLS + 1],
            label: [0; CLOUD_CAPACITY],
            clusters: [Cluster { start: 0, len: 0 }; MAX_CLUSTERS],
            n_clusters: 0,
            stats: DbscanStats {
                points: 0,
                noise: 0,
                small_clusters: 0,
                clusters_over_capacity: 0,
                cell_m: 0.0,
                rejected: 0,
            },
        }
    }

    /// The clusters of the last run.
    pub fn clusters(&self) -> &[Cluster] {
        &self.clusters[..self.n_clusters]
    }

    /// The clustered points of the last run; index with [`Cluster::range`].
    pub fn points(&self) -> &[Point2] {
        &self.out
    }

    /// The points of cluster `k`.
    pub fn cluster_points(&self, k: usize) -> &[Point2] {
        &self.out[self.clusters[k].range()]
    }

    /// Statistics of the last run.
    pub fn stats(&self) -> DbscanStats {
        self.stats
    }

    /// Clusters `points` (at most [`CLOUD_CAPACITY`] are taken; non-finite ones and ones beyond
    /// [`COORD_LIMIT_M`] are refused and counted).
    pub fn run<'a>(&mut self, points: impl IntoIterator<Item = &'a Point2>, cfg: &DbscanConfig) {
        self.n_clusters = 0;
        self.stats = DbscanStats::default();
        let eps_min = if cfg.eps_min_m.is_finite() && cfg.eps_min_m > 1e-3 {
            cfg.eps_min_m
        } else {
            0.08
        };
        let eps_max = if cfg.eps_max_m.is_finite() {
            cfg.eps_max_m.max(eps_min)
        } else {
            eps_min
        };

        // Gather into `out` (used as scratch here) and find the bounds.
        let mut n = 0;
        let (mut lo, mut hi) = (
            Point2::new(f32::MAX, f32::MAX),
            Point2::new(f32::MIN, f32::MIN),
        );
        for p in points {
            if n == CLOUD_CAPACITY {
                break;
            }
            if !(p.x.abs() <= COORD_LIMIT_M && p.y.abs() <= COORD_LIMIT_M) {
                self.stats.rejected += 1;
                continue;
            }
            self.out[n] = *p;
            lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
            n += 1;
        }
        self.stats.points = n as u32;
        if n == 0 {
            return;
        }

        // Grid: cells of ε_min / √2 (any two points in one cell are within ε_min of each
        // other), grown until the bounds fit.
        let mut cell = eps_min * core::f32::consts::FRAC_1_SQRT_2;
        let dims = |cell: f32| {
            (
                ((hi.x - lo.x) / cell) as usize + 1,
                ((hi.y - lo.y) / cell) as usize + 1,
            )
        };
        let (mut nx, mut ny) = dims(cell);
        while nx.saturating_mul(ny) > GRID_CELLS {
            cell *= 1.25;
            (nx, ny) = dims(cell);
        }
        let grid = Grid {
            origin: lo,
            cell,
            nx,
            ny,
        };
        self.stats.cell_m = cell;
        let cells = nx * ny;

        // Counting sort by cell into `sorted`.
        let starts = &mut self.cell_start[..=cells];
        starts.fill(0);
        for p in &self.out[..n] {
            starts[grid.index(*p) + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        {
            // Place points: a running cursor per cell lives in `cell_start[c]` (shifted back
            // afterwards), the standard in-place counting-sort trick.
            for p in &self.out[..n] {
                let c = grid.index(*p);
                let at = starts[c] as usize;
                self.sorted[at] = *p;
                starts[c] += 1;
            }
            for c in (1..=cells).rev() {
                starts[c] = starts[c - 1];
            }
            starts[0] = 0;
        }
        let starts = &self.cell_start[..=cells];
        let cell_range =
            |cx: usize, cy: usize| starts[cy * nx + cx] as usize..starts[cy * nx + cx + 1] as usize;

        // ε per cell from the 5 × 5 block count (every point of a cell shares it).
        let min_samples = cfg.min_samples.max(1) as usize;
        let span = 5.0 * cell;
        for cy in 0..ny {
            for cx in 0..nx {
                let own = cell_range(cx, cy);
                if own.is_empty() {
                    continue;
                }
                let mut count = 0usize;
                for y in cy.saturating_sub(2)..=(cy + 2).min(ny - 1) {
                    for x in cx.saturating_sub(2)..=(cx + 2).min(nx - 1) {
                        count += cell_range(x, y).len();
                    }
                }
                let e = (min_samples as f32 * span / count as f32).clamp(eps_min, eps_max);
                self.eps[own].fill(e);
            }
        }

        // Neighbours of point i: every j with |p_i − p_j| ≤ min(ε_i, ε_j), found by scanning
        // the cells within ε_i; `f` returns false to stop.
        let sorted = &self.sorted;
        let eps = &self.eps;
        let reach = |e: f32| (libm::ceilf(e / cell - 1e-4) as usize).max(1);
        let scan = |i: usize, f: &mut dyn FnMut(usize) -> bool| {
            let p = sorted[i];
            let e = eps[i];
            let r = reach(e);
            let (cx, cy) = grid.cell_xy(p);
            for y in cy.saturating_sub(r)..=(cy + r).min(ny - 1) {
                for x in cx.saturating_sub(r)..=(cx + r).min(nx - 1) {
                    for j in cell_range(x, y) {
                        let d = sorted[j] - p;
                        let m = e.min(eps[j]);
                        if d.x * d.x + d.y * d.y <= m * m && !f(j) {
                            return;
                        }
                    }
                }
            }
        };

        // Core points. Any two points of one cell are within ε_min (the cell's diagonal), so a
        // cell holding min_samples points is all core without a scan.
        for cy in 0..ny {
            for cx in 0..nx {
                let own = cell_range(cx, cy);
                if own.len() >= min_samples {
                    self.core[own].fill(true);
                    continue;
                }
                for i in own {
                    let mut count = 0usize;
                    scan(i, &mut |_| {
                        count += 1;
                        count < min_samples
                    });
                    self.core[i] = count >= min_samples;
                }
            }
        }

        // Union of core points, cell by cell: a cell's core points are one set (within ε_min of
        // each other); two cells' sets join at the first core pair within reach, and a pair of
        // cells already in one set is not scanned at all.
        for i in 0..n {
            self.parent[i] = if self.core[i] { i as u16 } else { NOISE };
        }
        let core = &self.core;
        let parent = &mut self.parent;
        for cy in 0..ny {
            for cx in 0..nx {
                let own = cell_range(cx, cy);
                let Some(rep) = own.clone().find(|&i| core[i]) else {
                    continue;
                };
                for i in own.clone().filter(|&i| core[i] && i != rep) {
                    parent[i] = rep as u16;
                }
                let e = eps[rep];
                let r = reach(e);
                let here = cy * nx + cx;
                for y in cy.saturating_sub(r)..=(cy + r).min(ny - 1) {
                    for x in cx.saturating_sub(r)..=(cx + r).min(nx - 1) {
                        if y * nx + x <= here {
                            continue;
                        }
                        let other = cell_range(x, y);
                        let Some(rep_b) = other.clone().find(|&j| core[j]) else {
                            continue;
                        };
                        if find(parent, rep) == find(parent, rep_b) {
                            continue;
                        }
                        let m = e.min(eps[rep_b]);
                        let linked = own.clone().filter(|&i| core[i]).any(|i| {
                            other.clone().filter(|&j| core[j]).any(|j| {
                                let d = sorted[j] - sorted[i];
                                d.x * d.x + d.y * d.y <= m * m
                            })
                        });
                        if linked {
                            let (a, b) = (find(parent, rep), find(parent, rep_b));
                            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                            parent[hi] = lo as u16;
                        }
                    }
                }
            }
        }
        // Border points: owned by the first core neighbour found.
        for j in 0..n {
            if core[j] {
                continue;
            }
            let mut owner = NOISE;
            scan(j, &mut |i| {
                if core[i] {
                    owner = i as u16;
                    false
                } else {
                    true
                }
            });
            parent[j] = owner;
        }

        // Roots → sizes (in `label`, per root), then cluster ids.
        self.label[..n].fill(0);
        for i in 0..n {
            let root = self.root_of(i);
            if let Some(r) = root {
                self.label[r] = self.label[r].saturating_add(1);
            }
        }
        let min_pts = cfg.min_cluster_points.max(1);
        // Assign ids in order of the root's index; sizes become ids.
        let mut next = 0usize;
        for r in 0..n {
            if !self.core[r] || self.parent[r] as usize != r {
                continue;
            }
            let size = self.label[r];
            if size < min_pts {
                self.stats.small_clusters += 1;
                self.label[r] = NOISE;
            } else if next == MAX_CLUSTERS {
                self.stats.clusters_over_capacity += 1;
                self.label[r] = NOISE;
            } else {
                self.clusters[next] = Cluster {
                    start: 0,
                    len: size,
                };
                self.label[r] = next as u16;
                next += 1;
            }
        }
        self.n_clusters = next;
        let mut acc = 0u16;
        for c in &mut self.clusters[..next] {
            c.start = acc;
            acc += c.len;
            c.len = 0;
        }
        let mut noise = 0u32;
        for i in 0..n {
            let id = self.root_of(i).map_or(NOISE, |r| self.label[r]);
            if id == NOISE {
                noise += 1;
                continue;
            }
            let c = &mut self.clusters[id as usize];
            self.out[(c.start + c.len) as usize] = self.sorted[i];
            c.len += 1;
        }
        self.stats.noise = noise;
    }

    /// The union–find root of point `i` (through its owner for a border point), if any.
    fn root_of(&mut self, i: usize) -> Option<usize> {
        let owner = if self.core[i] {
            i
        } else if self.parent[i] == NOISE {
            return None;
        } else {
            self.parent[i] as usize
        };
        Some(find(&mut self.parent, owner))
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn line(out: &mut std::vec::Vec<Point2>, a: Point2, b: Point2, n: usize) {
        for k in 0..n {
            let t = k as f32 / (n - 1) as f32;
            out.push(Point2::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t));
        }
    }

    fn blob(out: &mut std::vec::Vec<Point2>, c: Point2, n: usize, r: f32) {
        for k in 0..n {
            let a = k as f32 * 2.399;
            let rr = r * libm::sqrtf(k as f32 / n as f32);
            out.push(Point2::new(
                c.x + rr * libm::cosf(a),
                c.y + rr * libm::sinf(a),
            ));
        }
    }

    #[test]
    fn separates_blobs_and_drops_noise() {
        let mut pts = std::vec::Vec::new();
        blob(&mut pts, Point2::new(0.0, 0.0), 50, 0.05);
        blob(&mut pts, Point2::new(1.0, 0.0), 40, 0.05);
        blob(&mut pts, Point2::new(3.0, 3.0), 12, 0.02); // below 20: dropped
        pts.push(Point2::new(-2.0, 2.0));
        let mut d = Dbscan::new();
        d.run(&pts, &DbscanConfig::default());
        let mut sizes: std::vec::Vec<_> = d.clusters().iter().map(|c| c.len).collect();
        sizes.sort();
        assert_eq!(sizes, [40, 50]);
        assert_eq!(d.stats().noise, 13);
        assert_eq!(d.stats().small_clusters, 1);
        for k in 0..2 {
            let p = d.cluster_points(k);
            let c0 = p[0];
            assert!(p.iter().all(|q| q.distance(c0) < 0.2));
        }
    }

    #[test]
    fn sparse_wall_stays_one_cluster() {
        // 80 points over 4 m: 0.05 m spacing, 3 neighbours within ε_min; the rule widens ε.
        let mut pts = std::vec::Vec::new();
        line(&mut pts, Point2::new(0.0, 0.0), Point2::new(3.95, 0.0), 80);
        let mut d = Dbscan::new();
        d.run(&pts, &DbscanConfig::default());
        assert_eq!(d.clusters().len(), 1);
        assert_eq!(d.clusters()[0].len, 80);
        // With a fixed ε_min it falls apart into noise.
        let fixed = DbscanConfig {
            eps_max_m: 0.08,
            ..DbscanConfig::default()
        };
        d.run(&pts, &fixed);
        assert!(d.clusters().is_empty());
    }

    #[test]
    fn dense_box_near_wall_stays_apart() {
        let mut pts = std::vec::Vec::new();
        line(&mut pts, Point2::new(0.0, 0.0), Point2::new(4.0, 0.0), 2000);
        line(
            &mut pts,
            Point2::new(1.0, 0.16),
            Point2::new(1.6, 0.16),
            300,
        );
        let mut d = Dbscan::new();
        d.run(&pts, &DbscanConfig::default());
        let mut sizes: std::vec::Vec<_> = d.clusters().iter().map(|c| c.len).collect();
        sizes.sort();
        assert_eq!(sizes, [300, 2000]);
    }

    #[test]
    fn matches_plain_dbscan_with_fixed_eps() {
        // With ε_min = ε_max the rule is plain DBSCAN: compare with brute force.
        let mut pts = std::vec::Vec::new();
        let mut s = 1u32;
        for _ in 0..600 {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let x = (s >> 8) as f32 / (1 << 24) as f32 * 3.0;
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let y = (s >> 8) as f32 / (1 << 24) as f32 * 3.0;
            pts.push(Point2::new(x, y));
        }
        let cfg = DbscanConfig {
            eps_min_m: 0.1,
            eps_max_m: 0.1,
            min_samples: 5,
            min_cluster_points: 1,
        };
        let mut d = Dbscan::new();
        d.run(&pts, &cfg);
        // Brute force core points and their connected components.
        let n = pts.len();
        let pts = &pts;
        let nb = |i: usize| (0..n).filter(move |&j| pts[i].distance(pts[j]) <= 0.1);
        let core: std::vec::Vec<bool> = (0..n).map(|i| nb(i).count() >= 5).collect();
        let mut comp = std::vec![usize::MAX; n];
        let mut k = 0;
        for i in 0..n {
            if !core[i] || comp[i] != usize::MAX {
                continue;
            }
            let mut stack = std::vec![i];
            comp[i] = k;
            while let Some(a) = stack.pop() {
                for b in nb(a) {
                    if core[b] && comp[b] == usize::MAX {
                        comp[b] = k;
                        stack.push(b);
                    }
                }
            }
            k += 1;
        }
        let core_count = core.iter().filter(|c| **c).count();
        let clustered: usize = d.clusters().iter().map(|c| c.len as usize).sum();
        let reachable = (0..n)
            .filter(|&i| core[i] || nb(i).any(|j| core[j]))
            .count();
        assert_eq!(d.clusters().len(), k);
        assert_eq!(clustered, reachable);
        assert!(core_count > 0);
    }

    #[test]
    fn degenerate_inputs() {
        let mut d = Dbscan::new();
        let cfg = DbscanConfig::default();
        d.run(&[], &cfg);
        assert!(d.clusters().is_empty());
        d.run(&[Point2::new(1.0, 1.0)], &cfg);
        assert!(d.clusters().is_empty());
        let same = std::vec![Point2::new(2.0, -1.0); CLOUD_CAPACITY];
        d.run(&same, &cfg);
        assert_eq!(d.clusters().len(), 1);
        assert_eq!(d.clusters()[0].len as usize, CLOUD_CAPACITY);
        let bad = [Point2::new(f32::NAN, 0.0), Point2::new(0.0, f32::INFINITY)];
        d.run(&bad, &cfg);
        assert_eq!(d.stats().rejected, 2);
        // Far-apart points: the grid grows its cells instead of overflowing.
        let far = [
            Point2::new(-9e3, -9e3),
            Point2::new(9e3, 9e3),
            Point2::new(1e30, 0.0),
        ];
        d.run(&far, &cfg);
        assert!(d.stats().cell_m > 1.0);
        assert_eq!(d.stats().rejected, 1);
        assert!(d.clusters().is_empty());
        // Capacity-many distinct points in a grid pattern.
        let grid: std::vec::Vec<_> = (0..CLOUD_CAPACITY)
            .map(|i| Point2::new((i % 91) as f32 * 0.03, (i / 91) as f32 * 0.03))
            .collect();
        d.run(&grid, &cfg);
        assert_eq!(d.clusters().len(), 1);
    }
}
