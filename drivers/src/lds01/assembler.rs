//! The revolution assembler: decoded packets → [`Revolution`]s, with the sensor clock.
//!
//! ## When a revolution ends
//!
//! * packet 59 arrives: it is finished at once (no waiting for the next one);
//! * a packet arrives whose index is not after the last one (the index wrapped, so packets at
//!   the end of the revolution were lost);
//! * the caller's host clock shows no packet for [`AssemblerConfig::stale_after_us`]
//!   ([`Assembler::poll`], or a late packet in [`Assembler::push`]);
//! * the stream ends ([`Assembler::flush`]).
//!
//! So a lost packet never holds a revolution back. A revolution that ends with packets
//! missing is handed out all the same, flagged incomplete, with its missing packets counted.
//! A packet whose index equals the previous one is a repeat: counted and ignored. A packet kept
//! despite a failed checksum (`Count` policy) is used only if its index follows the previous
//! packet's; otherwise its index cannot be trusted and it is dropped and counted.
//!
//! ## Sensor clock (`docs/interfaces.md` §2)
//!
//! t = 0 at the start of the first packet; each packet slot lasts `1/rpm` seconds with rpm from
//! that packet's speed field (60 slots = `60/rpm` s, ~0.2 s at 300 rpm). A lost packet still
//! counts as an elapsed slot, known from the indices around it, at the last known speed. A speed
//! field outside [`MIN_PLAUSIBLE_RPM`, `MAX_PLAUSIBLE_RPM`] (a stalled motor, a `Count`-policy
//! packet with a bad checksum) does not move the clock's rate: the last plausible speed is used.
//!
//! Storage: two [`Revolution`]s (the one being filled and the last one finished), swapped
//! without copying.

use super::decoder::Decoded;
use super::packet::{PACKETS_PER_REV, READINGS_PER_PACKET, Repr};
use super::revolution::{EMPTY_READINGS, Reading, Revolution, bin_angle_rad, raw_to_bin};

/// Revolution buffers the assembler holds: the one being filled and the last finished one.
pub const ASSEMBLER_REVOLUTIONS: usize = 2;
/// Nominal LDS-01 speed, used for the clock until a plausible speed field has been seen.
pub const NOMINAL_RPM: f32 = 300.0;
/// Slowest speed field trusted for the clock.
pub const MIN_PLAUSIBLE_RPM: f32 = 60.0;
/// Fastest speed field trusted for the clock.
pub const MAX_PLAUSIBLE_RPM: f32 = 600.0;

/// Assembler settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AssemblerConfig {
    /// Shortest range counted valid, metres (LDS-01 spec: 0.12).
    pub min_range_m: f32,
    /// Longest range counted valid, metres (LDS-01 spec: 3.5; real units return up to ~4.2).
    pub max_range_m: f32,
    /// Host-clock silence after which a partial revolution is handed out, µs (default 0.5 s,
    /// 2.5 revolutions at 300 rpm).
    pub stale_after_us: u64,
}

impl Default for AssemblerConfig {
    fn default() -> Self {
        AssemblerConfig {
            min_range_m: 0.12,
            max_range_m: 3.5,
            stale_after_us: 500_000,
        }
    }
}

/// Counters kept by the assembler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AssemblerStats {
    /// Revolutions handed out.
    pub revolutions: u64,
    /// Revolutions handed out with fewer than 60 packets.
    pub incomplete_revolutions: u64,
    /// Packets missing from the revolutions handed out.
    pub missing_packets: u64,
    /// Packets received twice in a row (ignored).
    pub repeated_packets: u64,
    /// Packets with a failed checksum (kept under the `Count` policy) dropped all the same
    /// because their index does not follow the previous packet's: a corrupted index would
    /// put six readings at the wrong angles and split the revolution.
    pub out_of_sequence_bad_packets: u64,
    /// Packets with a good checksum whose speed field says the motor is stalled or far off
    /// speed (below [`MIN_PLAUSIBLE_RPM`]): the clock keeps the last plausible speed.
    pub stalled_packets: u64,
}

#[derive(Debug, Clone, Copy)]
struct Clock {
    /// Slot start time of the last packet, seconds.
    t_last: f64,
    last_index: u8,
    rpm: f32,
    /// `1 / rpm`: one packet slot, seconds (recomputed only when the speed changes).
    slot_s: f64,
    started: bool,
}

/// Assembles revolutions; see the module docs.
#[derive(Debug, Clone)]
pub struct Assembler {
    cfg: AssemblerConfig,
    bufs: [Revolution; ASSEMBLER_REVOLUTIONS],
    /// Index of the buffer being filled; the other one holds the last finished revolution.
    filling: usize,
    in_progress: bool,
    /// Index of the last packet put into the revolution being filled.
    last_in_rev: u8,
    last_host_us: Option<u64>,
    rpm_sum: f32,
    next_seq: u32,
    clock: Clock,
    stats: AssemblerStats,
}

impl Assembler {
    /// A new assembler.
    pub fn new(cfg: AssemblerConfig) -> Self {
        Assembler {
            cfg,
            bufs: [Revolution::empty(), Revolution::empty()],
            filling: 0,
            in_progress: false,
            last_in_rev: 0,
            last_host_us: None,
            rpm_sum: 0.0,
            next_seq: 0,
            clock: Clock {
                t_last: 0.0,
                last_index: 0,
                rpm: NOMINAL_RPM,
                slot_s: 1.0 / NOMINAL_RPM as f64,
                started: false,
            },
            stats: AssemblerStats::default(),
        }
    }

    /// Settings in force.
    pub fn config(&self) -> &AssemblerConfig {
        &self.cfg
    }

    /// Counters since construction.
    pub fn stats(&self) -> &AssemblerStats {
        &self.stats
    }

    /// The last revolution handed out, if any.
    pub fn last(&self) -> Option<&Revolution> {
        (self.stats.revolutions > 0).then(|| &self.bufs[1 - self.filling])
    }

    /// Sensor-clock time of the end of the last packet slot seen, seconds.
    pub fn sensor_time_s(&self) -> f64 {
        if self.clock.started {
            self.clock.t_last + self.clock.slot_s
        } else {
            0.0
        }
    }

    /// Adds one packet; returns the revolution it finished, if any. `host_us` is the caller's
    /// monotonic clock when the packet was decoded (`None` when replaying without one).
    ///
    /// At most one revolution is finished per packet: a packet that both closes the previous
    /// revolution (index wrap) and is packet 59 of a new one cannot exist, since a new
    /// revolution that starts at packet 59 holds just that packet and is finished next time.
    pub fn push(&mut self, packet: &Decoded, host_us: Option<u64>) -> Option<&Revolution> {
        self.push_packet(packet, host_us)
            .then(|| self.last())
            .flatten()
    }

    /// Like [`Assembler::push`] but returns only whether a revolution was finished (read it
    /// with [`Assembler::last`]); handy inside loops that keep borrowing the assembler.
    pub fn push_packet(&mut self, packet: &Decoded, host_us: Option<u64>) -> bool {
        let repr = &packet.repr;
        let k = repr.index;
        if usize::from(k) >= PACKETS_PER_REV {
            return false; // unreachable through the decoder; never index out of bounds
        }
        if packet.checksum_ok && repr.rpm() < MIN_PLAUSIBLE_RPM {
            self.stats.stalled_packets += 1;
        }
        if self.clock.started && k == self.clock.last_index {
            self.stats.repeated_packets += 1;
            return false;
        }
        let next = (usize::from(self.clock.last_index) + 1) % PACKETS_PER_REV;
        if !packet.checksum_ok && self.clock.started && usize::from(k) != next {
            self.stats.out_of_sequence_bad_packets += 1;
            return false;
        }
        let t = self.advance_clock(repr);

        let mut finished = false;
        if self.in_progress {
            let stale = match (host_us, self.last_host_us) {
                (Some(now), Some(last)) => now.saturating_sub(last) > self.cfg.stale_after_us,
                _ => false,
            };
            if k <= self.last_in_rev || stale {
                self.finish();
                finished = true;
            }
        }
        if !self.in_progress {
            self.start(t - f64::from(k) * self.clock.slot_s, host_us);
        }
        self.fill(packet);
        self.last_host_us = host_us.or(self.last_host_us);
        if usize::from(k) == PACKETS_PER_REV - 1 {
            // Two revolutions cannot finish on one packet: a new revolution that begins
            // with packet 59 is finished here only if nothing was finished above.
            if !finished {
                self.finish();
                finished = true;
            }
        }
        finished
    }

    /// Hands out the revolution being filled if the host clock shows it went stale.
    pub fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        let stale = self.in_progress
            && self
                .last_host_us
                .is_some_and(|last| now_us.saturating_sub(last) > self.cfg.stale_after_us);
        if stale {
            self.finish();
            self.last()
        } else {
            None
        }
    }

    /// Hands out the revolution being filled, whatever its state (end of stream).
    pub fn flush(&mut self) -> Option<&Revolution> {
        if self.in_progress {
            self.finish();
            self.last()
        } else {
            None
        }
    }

    fn advance_clock(&mut self, repr: &Repr) -> f64 {
        let c = &mut self.clock;
        let t = if c.started {
            let slots = (usize::from(repr.index) + PACKETS_PER_REV - usize::from(c.last_index))
                % PACKETS_PER_REV;
            c.t_last + slots as f64 * c.slot_s
        } else {
            c.started = true;
            0.0
        };
        let rpm = repr.rpm();
        if rpm != c.rpm && (MIN_PLAUSIBLE_RPM..=MAX_PLAUSIBLE_RPM).contains(&rpm) {
            c.rpm = rpm;
            c.slot_s = 1.0 / f64::from(rpm);
        }
        c.t_last = t;
        c.last_index = repr.index;
        t
    }

    fn start(&mut self, t_start_s: f64, host_us: Option<u64>) {
        let rev = &mut self.bufs[self.filling];
        rev.readings = EMPTY_READINGS;
        rev.seq = self.next_seq;
        rev.t_start_s = t_start_s;
        rev.host_time_us = host_us;
        rev.packets = 0;
        rev.present = 0;
        rev.bad_checksum_packets = 0;
        self.next_seq = self.next_seq.wrapping_add(1);
        self.rpm_sum = 0.0;
        self.in_progress = true;
    }

    fn fill(&mut self, packet: &Decoded) {
        let repr = &packet.repr;
        let k = usize::from(repr.index);
        let (min, max) = (self.cfg.min_range_m, self.cfg.max_range_m);
        let rev = &mut self.bufs[self.filling];
        for (j, raw) in repr.readings.iter().enumerate() {
            let d = raw_to_bin(READINGS_PER_PACKET * k + j);
            let range_m = f32::from(raw.range_mm) / 1000.0;
            rev.readings[d] = Reading {
                angle_rad: bin_angle_rad(d),
                range_m,
                intensity: raw.intensity,
                valid: raw.range_mm != 0 && range_m >= min && range_m <= max,
            };
        }
        rev.packets += 1;
        rev.present |= 1 << k;
        if !packet.checksum_ok {
            rev.bad_checksum_packets += 1;
        }
        self.rpm_sum += self.clock.rpm;
        self.last_in_rev = repr.index;
    }

    fn finish(&mut self) {
        let rev = &mut self.bufs[self.filling];
        rev.rpm = if rev.packets > 0 {
            self.rpm_sum / f32::from(rev.packets)
        } else {
            self.clock.rpm
        };
        rev.period_s = 60.0 / rev.rpm;
        self.stats.revolutions += 1;
        if !rev.is_complete() {
            self.stats.incomplete_revolutions += 1;
            self.stats.missing_packets += u64::from(rev.missing_packets());
        }
        self.in_progress = false;
        self.filling = 1 - self.filling;
    }
}

#[cfg(test)]
mod test {
    use super::super::packet::RawReading;
    use super::*;

    fn pkt(k: u8, rpm10: u16, range_mm: u16) -> Decoded {
        Decoded {
            repr: Repr {
                index: k,
                speed_raw: rpm10,
                readings: [RawReading {
                    intensity: 100,
                    range_mm,
                    reserved: 0,
                }; 6],
            },
            checksum_ok: true,
        }
    }

    #[test]
    fn full_revolutions() {
        let mut a = Assembler::new(AssemblerConfig::default());
        let mut seen = 0;
        for rev in 0..3u32 {
            for k in 0..60u8 {
                let done = a
                    .push(&pkt(k, 3000, 1000), None)
                    .map(|r| (r.seq, r.packets));
                if k == 59 {
                    assert_eq!(done, Some((rev, 60)));
                    seen += 1;
                } else {
                    assert_eq!(done, None);
                }
            }
        }
        assert_eq!(seen, 3);
        let last = a.last().unwrap();
        assert!(last.is_complete());
        assert_eq!(last.valid_count(), 360);
        assert!((last.rpm - 300.0).abs() < 1e-3);
        assert!((last.period_s - 0.2).abs() < 1e-6);
        // Third revolution starts after two revolutions of 0.2 s.
        assert!((last.t_start_s - 0.4).abs() < 1e-9);
        assert_eq!(a.stats().incomplete_revolutions, 0);
    }

    #[test]
    fn lost_tail_is_finished_on_wrap_and_clock_counts_lost_slots() {
        let mut a = Assembler::new(AssemblerConfig::default());
        for k in 0..50u8 {
            assert!(a.push(&pkt(k, 3000, 1000), None).is_none());
        }
        // Packets 50..59 and 0..1 lost; packet 2 of the next revolution arrives.
        let r = a.push(&pkt(2, 3000, 1000), None).unwrap();
        assert_eq!(r.packets, 50);
        assert_eq!(r.missing_packets(), 10);
        assert!(!r.is_complete());
        assert!(!r.has_packet(55));
        // Readings of a lost packet are invalid.
        assert!(!r.readings[raw_to_bin(6 * 55)].valid);
        assert_eq!(a.stats().missing_packets, 10);
        // The new revolution's slot 0 started 60 slots after the first one.
        for k in 3..60u8 {
            a.push(&pkt(k, 3000, 1000), None);
        }
        let r = a.last().unwrap();
        assert_eq!(r.seq, 1);
        assert_eq!(r.packets, 58);
        assert!((r.t_start_s - 0.2).abs() < 1e-9);
    }

    #[test]
    fn repeated_packet_ignored() {
        let mut a = Assembler::new(AssemblerConfig::default());
        a.push(&pkt(0, 3000, 1000), None);
        a.push(&pkt(0, 3000, 1000), None);
        assert_eq!(a.stats().repeated_packets, 1);
        for k in 1..60u8 {
            a.push(&pkt(k, 3000, 1000), None);
        }
        assert!(a.last().unwrap().is_complete());
    }

    #[test]
    fn range_window() {
        let cfg = AssemblerConfig::default();
        let mut a = Assembler::new(cfg);
        a.push(&pkt(0, 3000, 0), None);
        a.push(&pkt(1, 3000, 100), None);
        a.push(&pkt(2, 3000, 120), None);
        a.push(&pkt(3, 3000, 3500), None);
        a.push(&pkt(4, 3000, 3501), None);
        let r = a.flush().unwrap();
        let v = |k: usize| r.readings[raw_to_bin(6 * k)].valid;
        assert_eq!(
            [v(0), v(1), v(2), v(3), v(4)],
            [false, false, true, true, false]
        );
        assert_eq!(r.no_return_count(), 6);
        assert_eq!(r.readings[raw_to_bin(6 * 4)].range_m, 3.501);
    }

    #[test]
    fn stale_host_clock_flushes() {
        let mut a = Assembler::new(AssemblerConfig::default());
        a.push(&pkt(0, 3000, 1000), Some(1_000));
        a.push(&pkt(1, 3000, 1000), Some(4_000));
        assert!(a.poll(400_000).is_none());
        let r = a.poll(600_000).unwrap();
        assert_eq!(r.packets, 2);
        // A late packet after a silence also closes the revolution it cannot belong to.
        a.push(&pkt(5, 3000, 1000), Some(700_000));
        let r = a.push(&pkt(6, 3000, 1000), Some(2_000_000)).unwrap();
        assert_eq!(r.packets, 1);
        assert!(a.flush().is_some());
        assert!(a.flush().is_none());
    }

    #[test]
    fn implausible_speed_does_not_drive_clock() {
        let mut a = Assembler::new(AssemblerConfig::default());
        a.push(&pkt(0, 0, 1000), None);
        a.push(&pkt(1, 0, 1000), None);
        // Nominal 300 rpm → one slot = 1/300 s.
        assert!((a.sensor_time_s() - 2.0 / 300.0).abs() < 1e-9);
    }

    #[test]
    fn bad_checksum_packet_used_only_in_sequence() {
        let mut a = Assembler::new(AssemblerConfig::default());
        let bad = |k| Decoded {
            checksum_ok: false,
            ..pkt(k, 3000, 1000)
        };
        for k in 0..10u8 {
            a.push(&pkt(k, 3000, 1000), None);
        }
        assert!(a.push(&bad(10), None).is_none()); // in sequence: kept
        assert!(a.push(&bad(40), None).is_none()); // a corrupted index: dropped
        assert!(a.push(&bad(3), None).is_none()); // would split the revolution: dropped
        assert_eq!(a.stats().out_of_sequence_bad_packets, 2);
        for k in 11..60u8 {
            a.push(&pkt(k, 3000, 1000), None);
        }
        let r = a.last().unwrap();
        assert!(r.is_complete());
        assert_eq!(r.bad_checksum_packets, 1);
    }

    #[test]
    fn revolution_of_only_packet_59() {
        let mut a = Assembler::new(AssemblerConfig::default());
        for k in 0..30u8 {
            a.push(&pkt(k, 3000, 1000), None);
        }
        // Packet 59 arrives right after 29: same revolution, which it completes.
        let r = a.push(&pkt(59, 3000, 1000), None).unwrap();
        assert_eq!(r.packets, 31);
        // Then packet 59 again after a wrap of lost packets: counted as a repeat.
        assert!(a.push(&pkt(59, 3000, 1000), None).is_none());
        assert_eq!(a.stats().repeated_packets, 1);
    }
}
