//! The confusion matrix of the Method A evaluation as a PNG for people (`docs/`).
//!
//! Cells are shaded by the share of their truth row, with the count written in; drawn on the
//! lab's canvas ([`crate::canvas`]).

use std::path::Path;

use crate::canvas::Canvas;
use crate::eval_a::{PRED_COLS, Score, TRUTH_ROWS};

const CELL_W: usize = 160;
const CELL_H: usize = 44;
const LEFT: usize = 130;
const TOP: usize = 60;

/// Writes the confusion matrix of `score` to `path`.
pub fn write(path: &Path, score: &Score) -> std::io::Result<()> {
    let (rows, cols) = (TRUTH_ROWS.len(), PRED_COLS.len());
    let (w, h) = (LEFT + cols * CELL_W + 10, TOP + rows * CELL_H + 40);
    let mut c = Canvas::new(w, h);
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
    c.write_png(path)
}
