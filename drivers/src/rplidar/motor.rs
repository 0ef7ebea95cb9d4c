//! Starting and stopping an RPLIDAR: the motor line and the request order the SDK uses
//! (`docs/hardware.md` §1c, complaints §1d.7).
//!
//! * **A1, and A2 without the accessory board:** the Slamtec USB adapter switches the motor
//!   with **DTR**: asserted = motor stopped, released = spinning. Opening a port often leaves
//!   DTR asserted (the motor "comes to a stop"), so [`start`] always releases it first.
//! * **A2 with the accessory board:** `SET_MOTOR_PWM` (default 660, max 1023); pass the duty to
//!   [`start`] when the board says it has motor control.
//! * **Stop:** `STOP`, then the SDK's 100 ms before anything else, then the motor off.
//!
//! The sequences run against [`MotorLink`], which the serial transport implements and tests
//! mock; nothing here touches hardware directly.

use super::protocol::{cmd, delay, request, request_with_payload};

/// What the start/stop sequences need from a link.
pub trait MotorLink {
    /// The link's error.
    type Error;
    /// Sets DTR (`true` = asserted = motor stopped on the Slamtec adapter).
    fn set_dtr(&mut self, asserted: bool) -> Result<(), Self::Error>;
    /// Writes all of `bytes`.
    fn write_all(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
    /// Waits.
    fn delay_ms(&mut self, ms: u32);
}

/// Default PWM duty of the accessory board.
pub const DEFAULT_PWM: u16 = 660;
/// Highest PWM duty.
pub const MAX_PWM: u16 = 1023;

/// Spins the motor up and starts scanning: DTR released, PWM if given, `SCAN`, 10 ms.
pub fn start<L: MotorLink>(link: &mut L, pwm: Option<u16>) -> Result<(), L::Error> {
    link.set_dtr(false)?;
    if let Some(duty) = pwm {
        let mut buf = [0u8; 6];
        if let Some(n) = request_with_payload(
            cmd::SET_MOTOR_PWM,
            &duty.min(MAX_PWM).to_le_bytes(),
            &mut buf,
        ) {
            link.write_all(&buf[..n])?;
        }
    }
    link.write_all(&request(cmd::SCAN))?;
    link.delay_ms(delay::AFTER_SCAN_MS);
    Ok(())
}

/// Stops scanning and the motor: `STOP`, 100 ms, PWM 0 if the board has it, DTR asserted.
pub fn stop<L: MotorLink>(link: &mut L, pwm_board: bool) -> Result<(), L::Error> {
    link.write_all(&request(cmd::STOP))?;
    link.delay_ms(delay::AFTER_STOP_MS);
    if pwm_board {
        let mut buf = [0u8; 6];
        if let Some(n) = request_with_payload(cmd::SET_MOTOR_PWM, &0u16.to_le_bytes(), &mut buf) {
            link.write_all(&buf[..n])?;
        }
    }
    link.set_dtr(true)
}

#[cfg(test)]
mod test {
    use super::*;

    /// A mock link that records every call.
    #[derive(Default)]
    struct Mock {
        log: [Option<Call>; 8],
        n: usize,
    }

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Call {
        Dtr(bool),
        Write([u8; 6], usize),
        Delay(u32),
    }

    impl Mock {
        fn push(&mut self, c: Call) {
            self.log[self.n] = Some(c);
            self.n += 1;
        }
        fn calls(&self) -> impl Iterator<Item = Call> + '_ {
            self.log[..self.n].iter().flatten().copied()
        }
    }

    impl MotorLink for Mock {
        type Error = ();
        fn set_dtr(&mut self, asserted: bool) -> Result<(), ()> {
            self.push(Call::Dtr(asserted));
            Ok(())
        }
        fn write_all(&mut self, bytes: &[u8]) -> Result<(), ()> {
            let mut b = [0u8; 6];
            b[..bytes.len()].copy_from_slice(bytes);
            self.push(Call::Write(b, bytes.len()));
            Ok(())
        }
        fn delay_ms(&mut self, ms: u32) {
            self.push(Call::Delay(ms));
        }
    }

    #[test]
    fn a1_start_releases_dtr_before_scan_and_stop_waits_before_dtr() {
        let mut m = Mock::default();
        start(&mut m, None).unwrap();
        stop(&mut m, false).unwrap();
        let calls: [Call; 6] = [
            Call::Dtr(false),
            Call::Write([0xA5, 0x20, 0, 0, 0, 0], 2),
            Call::Delay(10),
            Call::Write([0xA5, 0x25, 0, 0, 0, 0], 2),
            Call::Delay(100),
            Call::Dtr(true),
        ];
        assert!(m.calls().eq(calls.iter().copied()));
    }

    #[test]
    fn a2_board_gets_pwm() {
        let mut m = Mock::default();
        start(&mut m, Some(5000)).unwrap();
        let second = m.calls().nth(1).unwrap();
        // Duty clamped to 1023 = 0x03FF.
        assert_eq!(
            second,
            Call::Write(
                [
                    0xA5,
                    0xF0,
                    0x02,
                    0xFF,
                    0x03,
                    0xA5 ^ 0xF0 ^ 0x02 ^ 0xFF ^ 0x03
                ],
                6
            )
        );
    }
}
