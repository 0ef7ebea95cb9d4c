//! Detection counts the score calibration is fitted from. Generated; do not edit.
//!
//! `umbra-lab calibrate rnqc-sim-4242.json rnqc-sim-4243.json rnqc-sim-4244.json rnqc-varied-4242.json rnqc-varied-4243.json rnqc-varied-4244.json` after `umbra-lab eval-world --family sim|varied --world on --seed 4242|4243|4244 --json F, umbra replay with --model rnq54's fp32 file`.
//! Per source (A, B, AB), class (chair, box, desk, door frame) and tenth of the score:
//! `[detections, on a piece of their class]`.

/// The counts, laid out as `perception::calibration::COUNTS_LEN` says.
pub const COUNTS: [u32; 240] = [
    0, 0, 0, 0, 0, 0, 9, 0, 130, 97, 274, 227, 258, 247, 113, 111, 15, 15, 2, 2,
    0, 0, 0, 0, 0, 0, 1, 0, 50, 20, 242, 96, 136, 43, 88, 48, 181, 104, 26, 25,
    0, 0, 0, 0, 0, 0, 0, 0, 30, 16, 210, 71, 161, 29, 105, 23, 9, 0, 0, 0,
    12, 0, 53, 2, 71, 1, 97, 1, 143, 1, 132, 3, 126, 1, 109, 3, 139, 8, 89, 25,
    0, 0, 0, 0, 707, 495, 1090, 856, 879, 743, 1005, 926, 1399, 1353, 2201, 2193, 3790, 3788, 271, 271,
    0, 0, 0, 0, 631, 275, 994, 516, 887, 543, 984, 743, 1024, 812, 909, 790, 1421, 1371, 220, 218,
    0, 0, 0, 0, 612, 378, 891, 546, 657, 453, 679, 543, 647, 568, 816, 777, 2625, 2619, 1119, 1117,
    0, 0, 0, 0, 151, 92, 238, 148, 229, 167, 263, 225, 375, 347, 990, 986, 1429, 1427, 232, 232,
    0, 0, 0, 0, 0, 0, 1, 1, 39, 38, 269, 263, 665, 663, 891, 891, 2889, 2889, 434, 434,
    0, 0, 0, 0, 0, 0, 0, 0, 13, 11, 136, 131, 182, 180, 677, 674, 5989, 5986, 4211, 4211,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 15, 14, 31, 31, 457, 456, 399, 399,
    0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 10, 10, 33, 33, 409, 409, 1036, 1036,
];
