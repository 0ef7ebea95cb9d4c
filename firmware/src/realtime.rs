//! Real-time scheduling of the frame loop (`[runtime] scheduling = "fifo"`): the calling
//! thread goes to `SCHED_FIFO` at the configured priority and the process's memory is locked
//! (`mlockall`), so neither other processes' load nor page faults can delay a frame. This is
//! what a robot gives its control loops; it needs root, `CAP_SYS_NICE` or an RLIMIT_RTPRIO (the
//! systemd unit sets `LimitRTPRIO=20` and `LimitMEMLOCK=infinity`). Without the permission the run goes on at normal priority and the report says
//! so. Reader threads started before keep normal priority: they block on their devices and
//! are short.

use crate::config::Scheduling;

/// Applies `scheduling` to the calling thread; returns what the run is scheduled as, for the
/// log and the report.
pub fn apply(scheduling: Scheduling, priority: u8) -> String {
    match scheduling {
        Scheduling::Normal => "normal priority (SCHED_OTHER)".to_owned(),
        Scheduling::Fifo => match fifo(priority) {
            Ok(locked) => format!(
                "real-time: SCHED_FIFO priority {priority}{}",
                if locked {
                    ", memory locked"
                } else {
                    " (memory not locked)"
                }
            ),
            Err(e) => {
                log::warn!(
                    "runtime.scheduling = \"fifo\": {e}; running at normal priority (run as root or grant CAP_SYS_NICE)"
                );
                "normal priority (SCHED_FIFO refused)".to_owned()
            }
        },
    }
}

/// `SCHED_FIFO` for this thread, then `mlockall`; `Ok(locked)` when the first worked.
#[cfg(target_os = "linux")]
fn fifo(priority: u8) -> Result<bool, String> {
    let param = libc::sched_param {
        sched_priority: i32::from(priority),
    };
    // SAFETY: `param` is a valid sched_param; pid 0 is the calling thread.
    #[allow(unsafe_code)]
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc != 0 {
        return Err(format!(
            "sched_setscheduler: {}",
            std::io::Error::last_os_error()
        ));
    }
    // SAFETY: plain flags; no memory is touched.
    #[allow(unsafe_code)]
    let locked = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } == 0;
    Ok(locked)
}

#[cfg(not(target_os = "linux"))]
fn fifo(_priority: u8) -> Result<bool, String> {
    Err("SCHED_FIFO is only set on Linux".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_scheduling_changes_nothing() {
        assert!(apply(Scheduling::Normal, 20).starts_with("normal"));
    }

    #[test]
    fn fifo_either_applies_or_says_why_not() {
        // In a thread of its own, so the test runner's threads keep their policy.
        let said = std::thread::spawn(|| apply(Scheduling::Fifo, 1))
            .join()
            .unwrap();
        assert!(
            said.starts_with("real-time: SCHED_FIFO priority 1") || said.contains("refused"),
            "{said}"
        );
    }
}
