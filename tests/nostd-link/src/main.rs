//! Link check: the protocol and perception cores in a `#![no_std]`, `#![no_main]` binary with
//! no `#[global_allocator]`. If any of it needed `alloc`, this would not link.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::panic::PanicInfo;

use drivers::lds01::{Lds01Config, Lds01Stream, PACKET_LEN, RawReading, Repr};
use drivers::lidar::detect::Detector;
use drivers::lidar::{AnyLidar, LidarConfig, LidarModel, RevolutionStream as _};
use perception::geometry::{Point2, Pose2};

/// Entry point: decode one emitted revolution and transform its points.
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    let mut stream = Lds01Stream::new(Lds01Config::default());
    let pose = Pose2::new(black_box(0.5), 0.0, black_box(0.1));
    let mut acc = 0.0f32;
    let mut packet = [0u8; PACKET_LEN];
    for k in 0..60u8 {
        let reading = RawReading {
            intensity: 100,
            range_mm: black_box(1500),
            reserved: 0,
        };
        let repr = Repr {
            index: k,
            speed_raw: 3000,
            readings: [reading; 6],
        };
        if repr.emit_into(&mut packet).is_ok() {
            stream.feed(&packet, None, |rev| {
                for r in rev.readings.iter().filter(|r| r.valid) {
                    acc += pose.transform(Point2::from_polar(r.range_m, r.angle_rad)).x;
                }
            });
        }
    }
    black_box(acc);
    black_box(stream.faults());
    // Every other model's stream and the detector, on the same bytes.
    let mut detector = Detector::new();
    detector.feed(black_box(&packet));
    black_box(detector.verdict());
    for model in LidarModel::ALL {
        let mut any = AnyLidar::new(model, &LidarConfig::default());
        any.feed(black_box(&packet), None, |rev| {
            black_box(rev.valid_count());
        });
        black_box(any.finish().map(|r| r.packets));
    }
    loop {}
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    loop {}
}
