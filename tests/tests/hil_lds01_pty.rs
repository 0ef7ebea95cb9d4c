//! Hardware-in-the-loop: the LDS-01 transport and decoder against a pseudo-terminal that
//! behaves like the LiDAR on a USB adapter.
//!
//! A writer thread owns the master side of a pty pair and plays the LiDAR: it waits for the
//! motor-start byte `b`, then writes simulated LDS-01 packets paced at the real link rate (one
//! 42-byte packet per 1/rpm s: 2,520 bytes per revolution, ~5 revolutions a second), with
//! garbage injected between packets. Our [`SerialLink`] opens the slave side through a symlink,
//! as a user would open `/dev/serial/by-id/…`. Half way through, the writer closes its side
//! (an unplug), waits, opens a new pty and points the symlink at it (a replug). The reader must
//! report the loss, reopen with back-off, resend `b`, and carry on; on drop it must send `e`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use drivers::lds01::{Lds01Config, Lds01Stream, PACKET_LEN};
use drivers::lidar::RevolutionStream as _;
use drivers::serial::{LinkRead, SerialConfig, SerialLink};
use serialport::TTYPort;
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::pty::{expect_byte, saw_stop_byte};
use sim::world::World;

const PHASE_REVOLUTIONS: usize = 10;
const GARBAGE_EVERY: usize = 7;
const GARBAGE: [u8; 5] = [0x00, 0x13, 0xA5, 0xFF, 0x62];

struct Link {
    master: TTYPort,
}

fn plug(link: &Path) -> Link {
    Link {
        master: umbra_tests::plug_pty(link, Duration::from_millis(100)),
    }
}

/// Writes `revolutions` of packets paced at the link rate, garbage every few packets.
fn play(master: &mut TTYPort, sim: &mut Lds01Sim, revolutions: usize) -> usize {
    let start = Instant::now();
    let mut t = 0.0f64;
    let mut garbage = 0;
    let mut packet = [0u8; PACKET_LEN];
    for n in 0..revolutions * 60 {
        t += sim.slot_s();
        sim.emit_packet(&mut packet);
        if n % GARBAGE_EVERY == GARBAGE_EVERY - 1 {
            master.write_all(&GARBAGE).unwrap();
            garbage += GARBAGE.len();
        }
        master.write_all(&packet).unwrap();
        let due = start + Duration::from_secs_f64(t);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            thread::sleep(wait);
        }
    }
    master.flush().unwrap();
    garbage
}

#[derive(Debug)]
struct Rev {
    seq: u32,
    complete: bool,
    host_us: u64,
    t_start: f64,
}

#[test]
fn pty_link_paced_with_garbage_and_replug() {
    let dir = std::env::temp_dir().join(format!("umbra-hil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link_path: PathBuf = dir.join("ttyLDS");
    let first = plug(&link_path);

    let (tx, rx) = mpsc::channel::<&'static str>();
    let writer_path = link_path.clone();
    let writer = thread::spawn(move || {
        let mut sim = Lds01Sim::new(World::random_room(9), Lds01SimConfig::default(), 9);
        let mut link = first;
        assert!(
            expect_byte(
                &mut link.master,
                b'b',
                Duration::from_secs(5),
                &mut Vec::new()
            ),
            "no motor-start byte"
        );
        let g1 = play(&mut link.master, &mut sim, PHASE_REVOLUTIONS);
        tx.send("unplugged").unwrap();
        drop(link); // unplug
        thread::sleep(Duration::from_millis(400));
        let mut link = plug(&writer_path); // replug
        assert!(
            expect_byte(
                &mut link.master,
                b'b',
                Duration::from_secs(10),
                &mut Vec::new()
            ),
            "no motor-start byte after reopen"
        );
        let g2 = play(&mut link.master, &mut sim, PHASE_REVOLUTIONS);
        tx.send("done").unwrap();
        (g1 + g2, saw_stop_byte(link.master, &[]))
    });

    let mut serial = SerialLink::open(link_path.to_str().unwrap(), SerialConfig::lds01())
        .expect("open pty through symlink");
    let mut stream = Lds01Stream::new(Lds01Config::default());
    let start = Instant::now();
    let mut buf = [0u8; 512];
    let (mut revs, mut lost, mut reopened, mut unplug_at) = (Vec::new(), 0, 0, None);
    let mut done_at = None;
    let deadline = Duration::from_secs(30);
    while start.elapsed() < deadline {
        let now = start.elapsed().as_micros() as u64;
        match serial.read(&mut buf) {
            LinkRead::Data(n) => {
                stream.feed(&buf[..n], Some(now), |r| {
                    revs.push(Rev {
                        seq: r.seq,
                        complete: r.is_complete(),
                        host_us: now,
                        t_start: r.t_start_s,
                    })
                });
            }
            LinkRead::Idle => {
                if let Some(r) = stream.poll(now) {
                    revs.push(Rev {
                        seq: r.seq,
                        complete: r.is_complete(),
                        host_us: now,
                        t_start: r.t_start_s,
                    })
                }
            }
            LinkRead::Lost(e) => {
                println!("lost: {e}");
                lost += 1;
                stream.link_reset();
            }
            LinkRead::Reopened => reopened += 1,
        }
        match rx.try_recv() {
            Ok("unplugged") => unplug_at = Some(revs.len()),
            Ok(_) => done_at = Some(Instant::now()),
            Err(_) => {}
        }
        if done_at.is_some_and(|t| t.elapsed() > Duration::from_millis(600)) {
            break;
        }
    }
    drop(serial); // sends `e`
    let (garbage, stopped) = writer.join().unwrap();

    let f = stream.faults();
    let complete = revs.iter().filter(|r| r.complete).count();
    println!(
        "revolutions {} (complete {complete}), lost {lost}, reopened {reopened}, garbage injected {garbage} B, skipped {} B, faults {f:?}",
        revs.len(),
        f.bytes_skipped
    );

    // In order, numbered without gaps, sensor clock increasing.
    for w in revs.windows(2) {
        assert_eq!(w[1].seq, w[0].seq + 1);
        assert!(w[1].t_start > w[0].t_start);
    }
    // The unplug was seen and survived.
    assert!(lost >= 1, "unplug not reported");
    assert!(reopened >= 1, "link not reopened");
    assert!(stopped, "no motor-stop byte on drop");
    let unplug_at = unplug_at.expect("writer never unplugged");
    // Phase 1: every revolution complete despite the garbage.
    let phase1 = &revs[..unplug_at.min(revs.len())];
    assert!(
        phase1.len() >= PHASE_REVOLUTIONS - 1,
        "phase 1: {} revolutions",
        phase1.len()
    );
    assert!(
        phase1.iter().all(|r| r.complete),
        "incomplete revolution before the unplug"
    );
    // Phase 2: after the replug, revolutions come back complete.
    let phase2_complete = revs[unplug_at..].iter().filter(|r| r.complete).count();
    assert!(
        phase2_complete >= PHASE_REVOLUTIONS - 2,
        "phase 2: {phase2_complete} complete"
    );
    // All injected garbage was skipped, and nothing else but what the unplug cut.
    assert!(f.bytes_skipped >= garbage as u64);
    assert_eq!(f.bad_checksum, 0);
    // Rate: complete revolutions in phase 1 arrive every ~200 ms (300 rpm ± jitter).
    let mut gaps: Vec<f64> = phase1
        .windows(2)
        .map(|w| (w[1].host_us - w[0].host_us) as f64 / 1000.0)
        .collect();
    gaps.sort_by(f64::total_cmp);
    let median = gaps[gaps.len() / 2];
    println!("median interval between revolutions: {median:.1} ms");
    assert!(
        (170.0..240.0).contains(&median),
        "median interval {median} ms"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
