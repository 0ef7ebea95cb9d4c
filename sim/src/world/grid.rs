//! A uniform grid over the world's primitives, and ray casting through it with a DDA walk
//! (Amanatides & Woo): a ray tests only the primitives in the cells it crosses and stops at the
//! first cell whose exit lies beyond the nearest hit found so far.
//!
//! Cells are [`CELL`] metres; the index is stored flat (CSR: per-cell offsets into one list).

use perception::geometry::Point2;

use super::Prim;

/// Cell size, metres.
pub const CELL: f32 = 0.25;

/// The index.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    origin: Point2,
    nx: usize,
    ny: usize,
    /// `items[start[c]..start[c + 1]]` are the primitives overlapping cell `c`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    /// Indexes `prims`.
    pub fn build(prims: &[Prim]) -> Grid {
        if prims.is_empty() {
            return Grid::default();
        }
        let (mut lo, mut hi) = (
            Point2::new(f32::MAX, f32::MAX),
            Point2::new(f32::MIN, f32::MIN),
        );
        for p in prims {
            let (a, b) = p.shape.bounds();
            lo = Point2::new(lo.x.min(a.x), lo.y.min(a.y));
            hi = Point2::new(hi.x.max(b.x), hi.y.max(b.y));
        }
        let origin = Point2::new(lo.x - CELL, lo.y - CELL);
        let nx = ((hi.x - origin.x) / CELL).ceil() as usize + 2;
        let ny = ((hi.y - origin.y) / CELL).ceil() as usize + 2;
        let mut grid = Grid {
            origin,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        let cells_of = |g: &Grid, p: &Prim| {
            let (a, b) = p.shape.bounds();
            let (x0, y0) = g.cell_of(a);
            let (x1, y1) = g.cell_of(b);
            (x0, y0, x1, y1)
        };
        for p in prims {
            let (x0, y0, x1, y1) = cells_of(&grid, p);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.start[y * nx + x + 1] += 1;
                }
            }
        }
        for c in 0..nx * ny {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        grid.items = vec![0; grid.start[nx * ny] as usize];
        for (i, p) in prims.iter().enumerate() {
            let (x0, y0, x1, y1) = cells_of(&grid, p);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = y * nx + x;
                    grid.items[fill[c] as usize] = i as u32;
                    fill[c] += 1;
                }
            }
        }
        grid
    }

    fn cell_of(&self, p: Point2) -> (usize, usize) {
        let x = ((p.x - self.origin.x) / CELL)
            .floor()
            .clamp(0.0, (self.nx - 1) as f32) as usize;
        let y = ((p.y - self.origin.y) / CELL)
            .floor()
            .clamp(0.0, (self.ny - 1) as f32) as usize;
        (x, y)
    }

    /// Nearest hit of the ray `o + t·d` (unit `d`), `t ≤ max_range`: (t, primitive, cos).
    pub fn raycast(
        &self,
        prims: &[Prim],
        o: Point2,
        d: Point2,
        max_range: f32,
    ) -> Option<(f32, usize, f32)> {
        if self.nx == 0 {
            return None;
        }
        let fx = (o.x - self.origin.x) / CELL;
        let fy = (o.y - self.origin.y) / CELL;
        if fx < 0.0 || fy < 0.0 || fx >= self.nx as f32 || fy >= self.ny as f32 {
            return None; // outside the indexed world: nothing to hit on this side
        }
        let (mut cx, mut cy) = (fx as isize, fy as isize);
        let step_x: isize = if d.x >= 0.0 { 1 } else { -1 };
        let step_y: isize = if d.y >= 0.0 { 1 } else { -1 };
        let inv_x = if d.x != 0.0 {
            1.0 / d.x.abs()
        } else {
            f32::INFINITY
        };
        let inv_y = if d.y != 0.0 {
            1.0 / d.y.abs()
        } else {
            f32::INFINITY
        };
        let next_x = if d.x >= 0.0 {
            (cx + 1) as f32 - fx
        } else {
            fx - cx as f32
        };
        let next_y = if d.y >= 0.0 {
            (cy + 1) as f32 - fy
        } else {
            fy - cy as f32
        };
        let mut t_max_x = next_x * CELL * inv_x;
        let mut t_max_y = next_y * CELL * inv_y;
        let (dt_x, dt_y) = (CELL * inv_x, CELL * inv_y);
        let mut best: Option<(f32, usize, f32)> = None;
        loop {
            let c = cy as usize * self.nx + cx as usize;
            for &i in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                if let Some((t, cos)) = prims[i as usize].shape.intersect(o, d)
                    && t <= max_range
                    && best.is_none_or(|b| t < b.0)
                {
                    best = Some((t, i as usize, cos));
                }
            }
            let t_exit = t_max_x.min(t_max_y);
            if best.is_some_and(|b| b.0 <= t_exit) || t_exit > max_range {
                return best;
            }
            if t_max_x < t_max_y {
                cx += step_x;
                t_max_x += dt_x;
            } else {
                cy += step_y;
                t_max_y += dt_y;
            }
            if cx < 0 || cy < 0 || cx as usize >= self.nx || cy as usize >= self.ny {
                return best;
            }
        }
    }
}
