//! Three LiDAR revolutions as one 64 × 384 × 3 image: the input of Method B.
//!
//! ## The encoding, bit-exactly
//!
//! * **Size:** [`RASTER_H`] = 64 rows × [`RASTER_W`] = 384 columns × [`RASTER_C`] = 3 channels,
//!   `u8`, row-major, channels interleaved (HWC): the byte of row `y`, column `x`, channel `c`
//!   is at `(y·384 + x)·3 + c`. This is the layout of an RGB PNG.
//! * **Channels:** channel 0 (red) is the **newest** revolution `t`, channel 1 (green) `t−1`,
//!   channel 2 (blue) `t−2`. (The study's PNGs ended up with the newest scan in the model's
//!   channel 0 as well, via OpenCV's BGR order; we state it instead of inheriting it.)
//! * **Column** = the reading's bin `d` in our angle convention: degrees **counter-clockwise**
//!   from the LiDAR's forward axis (REP 103, see `drivers::lds01::revolution`), 0..360.
//!   Columns 360..384 are always 0 (padding to a multiple of 32 for the network's strides).
//! * **Row** = `min(⌊range · 63 / max_range⌋, 63)` with `max_range` a setting (4 m default:
//!   4 m → row 63, one row ≈ 6.3 cm). Row 0 is the top of the image, i.e. nearest.
//! * **Pixel value:** 255 where a reading was drawn, 0 elsewhere.
//! * **Not drawn:** readings that are not valid (no return, or outside the driver's range
//!   window), and readings whose range is not a finite positive number. (The study drew
//!   no-return readings as 4 m, a line of false returns along row 63; we do not.)
//!
//! The encoder writes into a caller-provided buffer; it neither allocates nor panics.

use core::fmt;

/// Image rows (range axis).
pub const RASTER_H: usize = 64;
/// Image columns (angle axis): 360 one-degree bins padded to 384.
pub const RASTER_W: usize = 384;
/// Channels: newest, previous, the one before.
pub const RASTER_C: usize = 3;
/// Columns that carry readings.
pub const SCAN_COLUMNS: usize = 360;
/// Bytes of one raster.
pub const RASTER_LEN: usize = RASTER_H * RASTER_W * RASTER_C;
/// Value of a drawn pixel.
pub const HIT: u8 = 255;

/// Raster settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RasterConfig {
    /// Range that maps to the last row, metres (default 4.0).
    pub max_range_m: f32,
}

impl Default for RasterConfig {
    fn default() -> Self {
        RasterConfig { max_range_m: 4.0 }
    }
}

/// Why a raster could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum RasterError {
    /// The output buffer is not [`RASTER_LEN`] bytes.
    BadBufferLength,
    /// `max_range_m` is not a finite positive number.
    BadMaxRange,
}

impl fmt::Display for RasterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            RasterError::BadBufferLength => "raster buffer must be 64 × 384 × 3 bytes",
            RasterError::BadMaxRange => "raster max_range_m must be finite and positive",
        })
    }
}

impl core::error::Error for RasterError {}

/// One revolution as the raster needs it: range in metres by bin (degrees CCW), and whether
/// the reading is valid.
pub trait ScanBins {
    /// Range and validity of bin `d` (0..360).
    fn bin(&self, d: usize) -> (f32, bool);
}

/// A plain array of ranges by bin; 0 (or any non-positive value) means "not drawn".
impl ScanBins for [f32; SCAN_COLUMNS] {
    fn bin(&self, d: usize) -> (f32, bool) {
        let r = self[d % SCAN_COLUMNS];
        (r, r > 0.0)
    }
}

/// The row of a range, or `None` if it is not drawn.
pub fn row_for_range(range_m: f32, cfg: &RasterConfig) -> Option<usize> {
    if !(range_m.is_finite() && range_m > 0.0) {
        return None;
    }
    let row = range_m * (RASTER_H - 1) as f32 / cfg.max_range_m;
    Some(if row >= (RASTER_H - 1) as f32 {
        RASTER_H - 1
    } else {
        row as usize
    })
}

/// Checks the settings and calls `draw(row, column, channel)` for every pixel the three
/// revolutions set, `scans[0]` the newest (channel 0). The one definition of the encoding:
/// [`encode_hwc`] (PNG layout, the dataset) and [`encode_chw_f32`] (the model's input tensor,
/// the runtime) are both this walk.
pub fn for_each_hit<S: ScanBins + ?Sized>(
    scans: [&S; RASTER_C],
    cfg: &RasterConfig,
    mut draw: impl FnMut(usize, usize, usize),
) -> Result<(), RasterError> {
    if !(cfg.max_range_m.is_finite() && cfg.max_range_m > 0.0) {
        return Err(RasterError::BadMaxRange);
    }
    for (c, scan) in scans.iter().enumerate() {
        for d in 0..SCAN_COLUMNS {
            let (r, valid) = scan.bin(d);
            if !valid {
                continue;
            }
            if let Some(row) = row_for_range(r, cfg) {
                draw(row, d, c);
            }
        }
    }
    Ok(())
}

/// Writes the raster of three revolutions, `scans[0]` the newest, into `out` (HWC `u8`, the
/// layout of an RGB PNG; cleared first).
pub fn encode_hwc<S: ScanBins + ?Sized>(
    out: &mut [u8],
    scans: [&S; RASTER_C],
    cfg: &RasterConfig,
) -> Result<(), RasterError> {
    if out.len() != RASTER_LEN {
        return Err(RasterError::BadBufferLength);
    }
    out.fill(0);
    for_each_hit(scans, cfg, |row, col, c| {
        out[(row * RASTER_W + col) * RASTER_C + c] = HIT;
    })
}

/// Writes the same raster as the model's input tensor: `1 × 3 × 64 × 384` `f32`, planar (CHW),
/// a drawn pixel 1.0 (= 255 / 255, Ultralytics' input scaling), everything else 0.0; channel 0
/// is the newest revolution, as in the PNG Ultralytics trained on (it reads BGR and flips to
/// RGB). Cleared first; meant to be called on the tensor's own buffer, so no copy follows.
pub fn encode_chw_f32<S: ScanBins + ?Sized>(
    out: &mut [f32],
    scans: [&S; RASTER_C],
    cfg: &RasterConfig,
) -> Result<(), RasterError> {
    if out.len() != RASTER_LEN {
        return Err(RasterError::BadBufferLength);
    }
    out.fill(0.0);
    for_each_hit(scans, cfg, |row, col, c| {
        out[(c * RASTER_H + row) * RASTER_W + col] = 1.0;
    })
}

#[cfg(test)]
mod test {
    use super::*;

    fn scan(pairs: &[(usize, f32)]) -> [f32; SCAN_COLUMNS] {
        let mut s = [0.0; SCAN_COLUMNS];
        for &(d, r) in pairs {
            s[d] = r;
        }
        s
    }

    #[test]
    fn rows() {
        let cfg = RasterConfig::default();
        assert_eq!(row_for_range(0.0, &cfg), None);
        assert_eq!(row_for_range(-1.0, &cfg), None);
        assert_eq!(row_for_range(f32::NAN, &cfg), None);
        assert_eq!(row_for_range(0.01, &cfg), Some(0));
        assert_eq!(row_for_range(1.0, &cfg), Some(15)); // 15.75
        assert_eq!(row_for_range(2.0, &cfg), Some(31)); // 31.5
        assert_eq!(row_for_range(4.0, &cfg), Some(63));
        assert_eq!(row_for_range(9.0, &cfg), Some(63));
    }

    /// The golden image: every pixel that must be set, and a hash of the whole buffer.
    #[test]
    fn golden() {
        let newest = scan(&[(0, 1.0), (90, 2.0), (359, 4.2)]);
        let prev = scan(&[(0, 1.0), (180, 0.5)]);
        let oldest = scan(&[(45, 3.0), (100, -1.0)]);
        let mut out = [0xAAu8; RASTER_LEN];
        encode_hwc(
            &mut out,
            [&newest, &prev, &oldest],
            &RasterConfig::default(),
        )
        .unwrap();
        let set: std::vec::Vec<(usize, usize, usize)> = out
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0)
            .map(|(i, v)| {
                assert_eq!(*v, HIT);
                (i / (RASTER_W * 3), (i / 3) % RASTER_W, i % 3)
            })
            .collect();
        // (row, column, channel)
        assert_eq!(
            set,
            [
                (7, 180, 1),
                (15, 0, 0),
                (15, 0, 1),
                (31, 90, 0),
                (47, 45, 2),
                (63, 359, 0)
            ]
        );
        // FNV-1a of the whole buffer pins the layout, padding included.
        let hash = out.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
        });
        assert_eq!(hash, GOLDEN_HASH, "hash {hash:#x}");
    }

    const GOLDEN_HASH: u64 = 0x402e_a469_ee3b_c5f1;

    /// The tensor layout is the PNG layout transposed, 255 → 1.0.
    #[test]
    fn tensor_is_the_png_transposed() {
        let newest = scan(&[(0, 1.0), (90, 2.0), (359, 4.2)]);
        let prev = scan(&[(0, 1.0), (180, 0.5)]);
        let oldest = scan(&[(45, 3.0), (100, -1.0)]);
        let cfg = RasterConfig::default();
        let mut hwc = [0u8; RASTER_LEN];
        encode_hwc(&mut hwc, [&newest, &prev, &oldest], &cfg).unwrap();
        let mut chw = std::vec![0.5f32; RASTER_LEN];
        encode_chw_f32(&mut chw, [&newest, &prev, &oldest], &cfg).unwrap();
        for y in 0..RASTER_H {
            for x in 0..RASTER_W {
                for c in 0..RASTER_C {
                    let v = hwc[(y * RASTER_W + x) * RASTER_C + c];
                    assert_eq!(chw[(c * RASTER_H + y) * RASTER_W + x], f32::from(v) / 255.0);
                }
            }
        }
    }

    #[test]
    fn errors() {
        let s = [0.0f32; SCAN_COLUMNS];
        let mut short = [0u8; 10];
        assert_eq!(
            encode_hwc(&mut short, [&s, &s, &s], &RasterConfig::default()),
            Err(RasterError::BadBufferLength)
        );
        let mut out = [0u8; RASTER_LEN];
        let bad = RasterConfig { max_range_m: 0.0 };
        assert_eq!(
            encode_hwc(&mut out, [&s, &s, &s], &bad),
            Err(RasterError::BadMaxRange)
        );
    }
}
