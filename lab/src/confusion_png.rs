//! The confusion matrix of the Method A evaluation as a PNG for people (`docs/`).
//!
//! Cells are shaded by the share of their truth row, with the count written in; text uses a
//! built-in 5 × 7 pixel font (no font files, so the figure is the same on every machine).

use std::path::Path;

use crate::eval_a::{PRED_COLS, Score, TRUTH_ROWS};

const SCALE: usize = 2;
const CELL_W: usize = 160;
const CELL_H: usize = 44;
const LEFT: usize = 130;
const TOP: usize = 60;

/// 5 × 7 glyphs, one row per byte (bit 4 = left column).
fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [31, 2, 4, 2, 1, 17, 14],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        'a' => [0, 0, 14, 1, 15, 17, 15],
        'b' => [16, 16, 22, 25, 17, 17, 30],
        'c' => [0, 0, 14, 16, 16, 17, 14],
        'd' => [1, 1, 13, 19, 17, 17, 15],
        'e' => [0, 0, 14, 17, 31, 16, 14],
        'f' => [6, 9, 8, 28, 8, 8, 8],
        'g' => [0, 15, 17, 17, 15, 1, 14],
        'h' => [16, 16, 22, 25, 17, 17, 17],
        'i' => [4, 0, 12, 4, 4, 4, 14],
        'k' => [16, 16, 18, 20, 24, 20, 18],
        'l' => [12, 4, 4, 4, 4, 4, 14],
        'm' => [0, 0, 26, 21, 21, 17, 17],
        'n' => [0, 0, 22, 25, 17, 17, 17],
        'o' => [0, 0, 14, 17, 17, 17, 14],
        'p' => [0, 0, 30, 17, 30, 16, 16],
        'r' => [0, 0, 22, 25, 16, 16, 16],
        's' => [0, 0, 14, 16, 14, 1, 30],
        't' => [8, 8, 28, 8, 8, 9, 6],
        'u' => [0, 0, 17, 17, 17, 19, 13],
        'v' => [0, 0, 17, 17, 17, 10, 4],
        'w' => [0, 0, 17, 17, 21, 21, 10],
        'x' => [0, 0, 17, 10, 4, 10, 17],
        'y' => [0, 0, 17, 17, 15, 1, 14],
        'A' => [14, 17, 17, 31, 17, 17, 17],
        'M' => [17, 27, 21, 21, 17, 17, 17],
        '%' => [24, 25, 2, 4, 8, 19, 3],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        '/' => [0, 1, 2, 4, 8, 16, 0],
        ':' => [0, 12, 12, 0, 12, 12, 0],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '\\' => [0, 16, 8, 4, 2, 1, 0],
        _ => [0; 7],
    }
}

struct Canvas {
    w: usize,
    h: usize,
    px: Vec<u8>,
}

impl Canvas {
    fn rect(&mut self, x: usize, y: usize, w: usize, h: usize, c: [u8; 3]) {
        for yy in y..(y + h).min(self.h) {
            for xx in x..(x + w).min(self.w) {
                let i = 3 * (yy * self.w + xx);
                self.px[i..i + 3].copy_from_slice(&c);
            }
        }
    }

    fn text(&mut self, x: usize, y: usize, s: &str, c: [u8; 3]) {
        for (k, ch) in s.chars().enumerate() {
            let g = glyph(ch);
            for (row, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (16 >> col) != 0 {
                        self.rect(x + (k * 6 + col) * SCALE, y + row * SCALE, SCALE, SCALE, c);
                    }
                }
            }
        }
    }

    fn text_width(s: &str) -> usize {
        s.chars().count() * 6 * SCALE
    }
}

/// Writes the confusion matrix of `score` to `path`.
pub fn write(path: &Path, score: &Score) -> std::io::Result<()> {
    let (rows, cols) = (TRUTH_ROWS.len(), PRED_COLS.len());
    let (w, h) = (LEFT + cols * CELL_W + 10, TOP + rows * CELL_H + 40);
    let mut c = Canvas {
        w,
        h,
        px: vec![255; w * h * 3],
    };
    let black = [0, 0, 0];
    let (r, n) = score.object_accuracy();
    let title = format!(
        "Method A: truth \\ predicted, accuracy {:.2}%",
        100.0 * f64::from(r) / f64::from(n.max(1))
    );
    c.text(8, 8, &title, black);
    for (j, name) in PRED_COLS.iter().enumerate() {
        let x = LEFT + j * CELL_W + (CELL_W.saturating_sub(Canvas::text_width(name))) / 2;
        c.text(x, TOP - 22, name, black);
    }
    for (i, name) in TRUTH_ROWS.iter().enumerate() {
        c.text(8, TOP + i * CELL_H + CELL_H / 2 - 7, name, black);
        let total: u32 = score.confusion[i].iter().sum();
        for j in 0..cols {
            let v = score.confusion[i][j];
            let share = if total > 0 {
                f64::from(v) / f64::from(total)
            } else {
                0.0
            };
            let shade = (255.0 - 200.0 * share) as u8;
            let colour = if i == j {
                [shade, 255, shade]
            } else if v > 0 {
                [255, shade, shade]
            } else {
                [245, 245, 245]
            };
            let (x, y) = (LEFT + j * CELL_W, TOP + i * CELL_H);
            c.rect(x + 1, y + 1, CELL_W - 2, CELL_H - 2, colour);
            let label = v.to_string();
            c.text(
                x + (CELL_W.saturating_sub(Canvas::text_width(&label))) / 2,
                y + CELL_H / 2 - 7,
                &label,
                black,
            );
        }
    }
    let foot = format!(
        "views {}  doors found {}/{}",
        score.views, score.doors.0, score.doors.1
    );
    c.text(8, h - 24, &foot, [80, 80, 80]);
    let file = std::fs::File::create(path)?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().map_err(std::io::Error::other)?;
    wr.write_image_data(&c.px).map_err(std::io::Error::other)?;
    wr.finish().map_err(std::io::Error::other)?;
    Ok(())
}
