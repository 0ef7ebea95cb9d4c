//! The simulated robot's LiDAR as any model on the wire: the same scene, revolution by
//! revolution, sent as LDS-01 packets, LDROBOT frames (LDS-02, LD06, LD19) or RPLIDAR nodes
//! (A1, A2), at each model's native beam count.
//!
//! Each revolution of the scenario ([`Frame`]: 360 one-degree readings with the noise,
//! dropouts and rpm jitter of the reading model) is resampled at the model's own beam angles:
//! `n = sample_rate × period` beams a turn, evenly spaced, clockwise from the model's zero
//! (LDROBOT raw 0° = our 0°; RPLIDAR raw 0° = our 180°). A beam takes the range of the reading
//! whose bin it falls in, so every model sees the same ranges and the pipeline's objects can be
//! compared across models. For the LDS-02 the inverse of the LD08 geometry correction is
//! applied (raw distance and raw angle), so the driver's correction gives the scene back.
//! Sensor clocks follow `docs/interfaces.md` §2: LDROBOT frames carry millisecond stamps (wrapping
//! at 30000), RPLIDAR nodes carry nothing.

use drivers::ldrobot::{self, FrameRepr, POINTS, RawPoint};
use drivers::lidar::points::bin_of;
use drivers::lidar::{Family, LidarModel};
use drivers::rplidar::{Node, SCAN_DESCRIPTOR};

use crate::scenario::{Frame, OdomSample, Scenario};

/// The LD08 correction's angle shift far out, degrees (`atan 0.11923`).
const LD08_FAR_SHIFT_DEG: f32 = 6.8;

/// Beams a turn of `model` at `period_s` (LDROBOT: a whole number of 12-point frames, rounded
/// down).
pub fn beams_per_revolution(model: LidarModel, period_s: f64) -> usize {
    let n = (f64::from(model.sample_rate_hz()) * period_s)
        .round()
        .max(12.0) as usize;
    match model.family() {
        Family::Ldrobot => n.div_ceil(POINTS) * POINTS,
        _ => n,
    }
}

fn reading_at(frame: &Frame, ccw_deg: f32) -> (u16, u16) {
    let r = &frame.readings[bin_of(ccw_deg)].raw;
    (r.range_mm, r.intensity)
}

/// Appends one revolution of `frame` as LDROBOT frames of `model` to `out`.
pub fn emit_ldrobot(model: LidarModel, frame: &Frame, out: &mut Vec<u8>) {
    let period = if frame.rpm > 0.0 {
        60.0 / f64::from(frame.rpm)
    } else {
        0.2
    };
    let n = beams_per_revolution(model, period);
    let rate = f64::from(model.sample_rate_hz());
    let speed_dps = (360.0 / period).round() as u16;
    let ld08 = model == LidarModel::Lds02;
    let mut buf = [0u8; ldrobot::FRAME_LEN];
    for f in 0..n / POINTS {
        let mut repr = FrameRepr {
            speed_dps,
            ..FrameRepr::default()
        };
        // Raw angles on the frame's 0.01° grid, and each point aimed at the angle the driver's
        // interpolation will give it.
        let first = 12 * f;
        let start_c = ((36_000 * first) / n) as u32 % 36_000;
        let end_c = ((36_000 * (first + POINTS - 1)) / n) as u32 % 36_000;
        repr.start_angle_cdeg = start_c as u16;
        repr.end_angle_cdeg = end_c as u16;
        let raw_angles: [f32; POINTS] = core::array::from_fn(|i| repr.point_angle_deg(i));
        for (p, &raw) in repr.points.iter_mut().zip(&raw_angles) {
            let (mut mm, mut intensity) = reading_at(frame, 360.0 - raw);
            let mut raw_mm = f32::from(mm);
            if ld08 {
                // The corrected beam points about 6° past the raw angle (atan 0.11923 far
                // out): aim there, then find the range whose own shift lands on a reading of
                // that range. A beam aimed at no return returns nothing.
                (mm, intensity) = reading_at(frame, 360.0 - raw + LD08_FAR_SHIFT_DEG);
                for _ in 0..4 {
                    if mm == 0 {
                        break;
                    }
                    let (_, shift) =
                        ldrobot::ld08_correct(ldrobot::ld08_raw_distance(f32::from(mm)));
                    let (m2, i2) = reading_at(frame, 360.0 - raw + shift);
                    if m2 == mm {
                        break;
                    }
                    (mm, intensity) = (m2, i2);
                }
                raw_mm = if mm == 0 {
                    0.0
                } else {
                    ldrobot::ld08_raw_distance(f32::from(mm))
                };
            }
            *p = RawPoint {
                distance_mm: raw_mm.round().clamp(0.0, 65_535.0) as u16,
                confidence: if mm == 0 {
                    0
                } else {
                    (intensity >> 2).clamp(1, 255) as u8
                },
            };
        }
        let t = frame.t_start_s + first as f64 / rate;
        repr.timestamp_ms =
            ((t * 1000.0).round() as u64 % u64::from(ldrobot::frame::TIMESTAMP_WRAP_MS)) as u16;
        // A 47-byte buffer always fits.
        let _ = repr.emit_into(&mut buf);
        out.extend_from_slice(&buf);
    }
}

/// Appends one revolution of `frame` as RPLIDAR SCAN nodes to `out`.
pub fn emit_rplidar(model: LidarModel, frame: &Frame, out: &mut Vec<u8>) {
    let period = if frame.rpm > 0.0 {
        60.0 / f64::from(frame.rpm)
    } else {
        0.2
    };
    let n = beams_per_revolution(model, period);
    for j in 0..n {
        let angle_q6 = ((360 * 64 * j) / n) as u16;
        let raw = f32::from(angle_q6) / 64.0;
        let (mm, intensity) = reading_at(frame, 180.0 - raw);
        let node = Node {
            start: j == 0,
            quality: if mm == 0 {
                0
            } else {
                (intensity >> 4).clamp(1, 63) as u8
            },
            angle_q6,
            distance_q2: mm.saturating_mul(4),
        };
        out.extend_from_slice(&node.to_bytes());
    }
}

/// A simulated robot whose LiDAR is `model`: plays a scenario revolution by revolution as
/// that model's bytes.
#[derive(Debug, Clone)]
pub struct WireSim {
    scenario: Scenario,
    model: LidarModel,
    frame: Box<Frame>,
    odom: Vec<OdomSample>,
    started: bool,
}

impl WireSim {
    /// Plays `scenario` as `model`.
    pub fn new(scenario: Scenario, model: LidarModel) -> Self {
        WireSim {
            scenario,
            model,
            frame: Box::default(),
            odom: Vec::new(),
            started: false,
        }
    }

    /// The model.
    pub fn model(&self) -> LidarModel {
        self.model
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The last revolution simulated (its truth).
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Takes the encoder/compass samples simulated so far.
    pub fn drain_odometry(&mut self) -> std::vec::Drain<'_, OdomSample> {
        self.odom.drain(..)
    }

    /// Appends the next revolution's bytes to `out` (an RPLIDAR's first revolution is
    /// preceded by the SCAN response descriptor, as after a real SCAN request).
    pub fn emit_revolution(&mut self, out: &mut Vec<u8>) {
        self.scenario.next_frame(&mut self.frame, &mut self.odom);
        match self.model.family() {
            Family::Lds01 => self.frame.emit(out),
            Family::Ldrobot => emit_ldrobot(self.model, &self.frame, out),
            Family::Rplidar => {
                if !self.started {
                    out.extend_from_slice(&SCAN_DESCRIPTOR.to_bytes());
                }
                emit_rplidar(self.model, &self.frame, out);
            }
        }
        self.started = true;
    }

    /// Appends `n` revolutions.
    pub fn emit_revolutions(&mut self, n: usize, out: &mut Vec<u8>) {
        for _ in 0..n {
            self.emit_revolution(out);
        }
    }

    /// Bytes of one unit on the wire (packet, frame, node), for corrupting unit by unit.
    pub fn unit_len(&self) -> usize {
        match self.model.family() {
            Family::Lds01 => drivers::lds01::PACKET_LEN,
            Family::Ldrobot => ldrobot::FRAME_LEN,
            Family::Rplidar => drivers::rplidar::NODE_LEN,
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::scenario::ScenarioConfig;
    use drivers::lidar::{AnyLidar, LidarConfig, RevolutionStream};

    /// Every model's bytes, decoded by its driver, give back the scene's ranges bin by bin.
    #[test]
    fn every_model_decodes_to_the_same_scan() {
        for model in LidarModel::ALL {
            let mut sim = WireSim::new(Scenario::new(3, &ScenarioConfig::standard()), model);
            let mut bytes = Vec::new();
            sim.emit_revolutions(4, &mut bytes);
            let truth = sim.frame().ranges_m();
            let cfg = LidarConfig {
                min_range_m: Some(0.12),
                max_range_m: Some(3.5),
                ..LidarConfig::default()
            };
            let mut stream = AnyLidar::new(model, &cfg);
            let mut revs = 0;
            stream.feed(&bytes, None, |_| revs += 1);
            let _ = stream.finish();
            let rev = stream.last_revolution().expect("a last revolution").clone();
            assert!(revs >= 3, "{model}: {revs}");
            assert!(rev.is_complete(), "{model}: {} sectors", rev.packets);
            let (mut same, mut total) = (0, 0);
            for d in 0..360 {
                if truth[d] > 0.12 && truth[d] < 3.5 {
                    total += 1;
                    if (rev.readings[d].range_m - truth[d]).abs() < 0.01 {
                        same += 1;
                    } else if std::env::var("WIRE_DEBUG").is_ok() {
                        println!(
                            "{model} bin {d}: got {} truth {} neighbours {} {}",
                            rev.readings[d].range_m,
                            truth[d],
                            truth[(d + 359) % 360],
                            truth[(d + 1) % 360]
                        );
                    }
                }
            }
            let share = same as f32 / total as f32;
            // The LD08's beams bend by a range-dependent 0–7°: next to a range jump or a
            // dropout a bin can be skipped or taken by a neighbour's beam (94 % agree here,
            // every miss beside an edge). The other models' beams are straight.
            let need = if model == LidarModel::Lds02 {
                0.9
            } else {
                0.97
            };
            assert!(share > need, "{model}: {same}/{total} bins agree");
            let f = stream.faults();
            assert_eq!(f.bytes_skipped, 0, "{model}");
            assert_eq!(f.implausible_frames, 0, "{model}");
        }
    }
}
