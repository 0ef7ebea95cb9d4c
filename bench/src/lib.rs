//! Peers for umbra's benchmarks, and the stream the LDS-01 benchmark decodes.
//!
//! [`vendor_poll`] is the LDS-01 polling loop of the vendor's ROS driver
//! (`ROBOTIS-GIT/hls_lfcd_lds_driver`, `lfcd_laser.cpp`) as ported line for line by the
//! `hls_lfcd_lds_driver` crate (0.1.7, `LFCDLaser::read`): wait for `FA A0`, read the rest of
//! the 2,520-byte revolution in one go, then keep each 42-byte slot whose first two bytes are
//! `FA` and the expected index. No checksum, no resync inside a revolution. That crate only
//! reads from a `serialport::TTYPort`, so the same loop is reproduced here over any
//! `std::io::Read`, so that both decoders can be fed the same bytes from memory.
#![deny(missing_docs)]

use std::io::Read;

use sim::corrupt::{Corruption, corrupt};
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::world::World;

/// The peer's reading, as in `hls_lfcd_lds_driver::LaserReading`.
#[derive(Debug, Clone)]
pub struct LaserReading {
    /// Ranges in mm by degree (index 359 − raw).
    pub ranges: [u16; 360],
    /// Intensities by degree.
    pub intensities: [u16; 360],
    /// rpm of the last good packet.
    pub rpms: u16,
}

/// `LFCDLaser::read` of `hls_lfcd_lds_driver` 0.1.7 over any reader; `None` at end of input.
pub fn vendor_poll(serial: &mut impl Read, buff: &mut [u8; 2520]) -> Option<LaserReading> {
    let mut start_count: usize = 0;
    let mut scan = LaserReading {
        ranges: [0; 360],
        intensities: [0; 360],
        rpms: 0,
    };
    loop {
        serial
            .read_exact(std::slice::from_mut(&mut buff[start_count]))
            .ok()?;
        if start_count == 0 {
            if buff[start_count] == 0xFA {
                start_count = 1
            }
        } else if start_count == 1 {
            if buff[start_count] == 0xA0 {
                serial.read_exact(&mut buff[2..]).ok()?;
                for i in (0..buff.len()).step_by(42) {
                    if buff[i] == 0xFA && usize::from(buff[i + 1]) == (0xA0 + i / 42) {
                        let b_rmp0: u16 = buff[i + 3] as u16;
                        let b_rmp1: u16 = buff[i + 2] as u16;
                        scan.rpms = (b_rmp0 << 8 | b_rmp1) / 10;
                        for j in ((i + 4)..(i + 40)).step_by(6) {
                            let index = 6 * (i / 42) + (j - 4 - i) / 6;
                            let b0: u16 = buff[j] as u16;
                            let b1: u16 = buff[j + 1] as u16;
                            let b2: u16 = buff[j + 2] as u16;
                            let b3: u16 = buff[j + 3] as u16;
                            scan.ranges[359 - index] = (b3 << 8) + b2;
                            scan.intensities[359 - index] = (b1 << 8) + b0;
                        }
                    }
                }
                return Some(scan);
            } else {
                start_count = 0;
            }
        }
    }
}

/// About `bytes` of simulated LDS-01 stream (whole revolutions) sent through `corruption`.
pub fn stream(bytes: usize, corruption: Corruption, seed: u64) -> Vec<u8> {
    let mut sim = Lds01Sim::new(World::random_room(seed), Lds01SimConfig::default(), seed);
    let mut clean = Vec::with_capacity(bytes + 2520);
    sim.emit_revolutions(bytes.div_ceil(2520), &mut clean);
    corrupt(clean.chunks(42), corruption, seed).bytes
}

/// Median wall time of 200 calls of `f`, milliseconds: how the peer ratios are taken (the
/// peers report medians too).
pub fn median_ms(f: &mut dyn FnMut()) -> f64 {
    let mut v: Vec<f64> = (0..200)
        .map(|_| {
            let t = std::time::Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[cfg(test)]
mod test {
    use super::*;
    use drivers::lds01::{Lds01Config, Lds01Stream};
    use drivers::lidar::RevolutionStream as _;

    #[test]
    fn peer_port_agrees_with_ours_on_clean_bytes() {
        let bytes = stream(20 * 2520, Corruption::NONE, 3);
        let mut ours = Vec::new();
        Lds01Stream::new(Lds01Config::default()).feed(&bytes, None, |r| {
            ours.push(r.readings.map(|x| (x.range_m * 1000.0).round() as u16))
        });
        let mut cursor = &bytes[..];
        let mut buff = [0u8; 2520];
        let mut theirs = Vec::new();
        while let Some(scan) = vendor_poll(&mut cursor, &mut buff) {
            theirs.push(scan.ranges);
        }
        assert_eq!(ours.len(), 20);
        assert_eq!(ours, theirs);
    }
}
