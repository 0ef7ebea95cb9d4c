//! The compass: an LSM303AGR magnetometer through the `lsm303agr` crate, generic over any
//! embedded-hal 1.0 I²C bus (on a Pi: `linux-embedded-hal`'s `I2cdev` on `/dev/i2c-1`; in tests:
//! `embedded-hal-mock`). Readings are in microtesla in the sensor's frame, which umbra takes as
//! the robot frame (mount the chip x forward, y left; a yaw offset is the config's
//! `compass.offset_deg`).
//!
//! The magnetometer runs in one-shot high-resolution mode: each [`Lsm303Compass::read_ut`]
//! starts a measurement and waits for it at most [`MAX_POLLS`] status polls, 1 ms apart, so a
//! dead chip is a counted error, never a hang.

use core::fmt;

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;
use lsm303agr::interface::I2cInterface;
use lsm303agr::mode::MagOneShot;
use lsm303agr::{Lsm303agr, MagMode, MagOutputDataRate};

/// Status polls before a reading times out (1 ms apart; a high-resolution one-shot takes ~10 ms).
pub const MAX_POLLS: u32 = 50;

/// Compass errors.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompassError<E> {
    /// The bus failed.
    Bus(E),
    /// The driver refused the input.
    InvalidInput,
    /// No measurement within [`MAX_POLLS`] polls.
    Timeout,
}

impl<E> From<lsm303agr::Error<E>> for CompassError<E> {
    fn from(e: lsm303agr::Error<E>) -> Self {
        match e {
            lsm303agr::Error::Comm(e) => CompassError::Bus(e),
            lsm303agr::Error::InvalidInputData => CompassError::InvalidInput,
        }
    }
}

impl<E: fmt::Debug> fmt::Display for CompassError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompassError::Bus(e) => write!(f, "compass: I2C error {e:?}"),
            CompassError::InvalidInput => f.write_str("compass: invalid input to the driver"),
            CompassError::Timeout => f.write_str("compass: no measurement ready in time"),
        }
    }
}

/// An LSM303AGR magnetometer.
pub struct Lsm303Compass<I2C, D> {
    dev: Lsm303agr<I2cInterface<I2C>, MagOneShot>,
    delay: D,
}

impl<I2C: I2c, D: DelayNs> Lsm303Compass<I2C, D> {
    /// Configures the magnetometer (high resolution, 10 Hz) on `i2c`.
    pub fn new(i2c: I2C, mut delay: D) -> Result<Self, CompassError<I2C::Error>> {
        let mut dev = Lsm303agr::new_with_i2c(i2c);
        dev.set_mag_mode_and_odr(&mut delay, MagMode::HighResolution, MagOutputDataRate::Hz10)?;
        Ok(Lsm303Compass { dev, delay })
    }

    /// One reading, µT, sensor frame.
    pub fn read_ut(&mut self) -> Result<[f32; 3], CompassError<I2C::Error>> {
        for _ in 0..MAX_POLLS {
            match self.dev.magnetic_field() {
                Ok(m) => {
                    let (x, y, z) = m.xyz_nt();
                    return Ok([x as f32 / 1000.0, y as f32 / 1000.0, z as f32 / 1000.0]);
                }
                Err(nb::Error::WouldBlock) => self.delay.delay_ms(1),
                Err(nb::Error::Other(e)) => return Err(e.into()),
            }
        }
        Err(CompassError::Timeout)
    }

    /// Gives the bus back.
    pub fn destroy(self) -> I2C {
        self.dev.destroy()
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use embedded_hal_mock::eh1::delay::NoopDelay;
    use embedded_hal_mock::eh1::i2c::{Mock, Transaction as T};

    // Retyped from the LSM303AGR datasheet (not imported from the driver).
    const MAG: u8 = 0b001_1110;
    const CFG_REG_A_M: u8 = 0x60;
    const STATUS_REG_M: u8 = 0x67;
    const OUTX_L_REG_M: u8 = 0x68;
    const AUTO_INCREMENT: u8 = 0x80;
    /// Reset value of CFG_REG_A_M: idle mode.
    const IDLE: u8 = 0x03;

    #[test]
    fn configures_then_reads_microtesla() {
        let i2c = Mock::new(&[
            // High resolution, 10 Hz, still idle.
            T::write(MAG, std::vec![CFG_REG_A_M, IDLE]),
            // One-shot: not ready, start a measurement, poll until ready, read six bytes.
            T::write_read(MAG, std::vec![STATUS_REG_M], std::vec![0]),
            T::write_read(MAG, std::vec![CFG_REG_A_M], std::vec![0]),
            T::write(MAG, std::vec![CFG_REG_A_M, 1]),
            T::write_read(MAG, std::vec![STATUS_REG_M], std::vec![0]),
            T::write_read(MAG, std::vec![CFG_REG_A_M], std::vec![1]),
            T::write_read(MAG, std::vec![STATUS_REG_M], std::vec![0xFF]),
            T::write_read(
                MAG,
                std::vec![OUTX_L_REG_M | AUTO_INCREMENT],
                // x = 100, y = −200, z = 300 LSB at 150 nT/LSB.
                std::vec![100, 0, 0x38, 0xFF, 0x2C, 0x01],
            ),
        ]);
        let mut c = Lsm303Compass::new(i2c, NoopDelay).unwrap();
        let m = c.read_ut().unwrap();
        assert_eq!(m, [15.0, -30.0, 45.0]);
        c.destroy().done();
    }

    #[test]
    fn a_chip_that_never_gets_ready_times_out() {
        let mut tr = std::vec![T::write(MAG, std::vec![CFG_REG_A_M, IDLE])];
        // First poll starts the measurement; every later one finds it still running.
        tr.push(T::write_read(MAG, std::vec![STATUS_REG_M], std::vec![0]));
        tr.push(T::write_read(MAG, std::vec![CFG_REG_A_M], std::vec![0]));
        tr.push(T::write(MAG, std::vec![CFG_REG_A_M, 1]));
        for _ in 1..MAX_POLLS {
            tr.push(T::write_read(MAG, std::vec![STATUS_REG_M], std::vec![0]));
            tr.push(T::write_read(MAG, std::vec![CFG_REG_A_M], std::vec![1]));
        }
        let mut c = Lsm303Compass::new(Mock::new(&tr), NoopDelay).unwrap();
        assert!(matches!(c.read_ut(), Err(CompassError::Timeout)));
        c.destroy().done();
    }
}
