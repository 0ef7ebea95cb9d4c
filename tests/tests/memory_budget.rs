//! Keeps `memory-budget.md` true: every fixed buffer in the code has a row whose capacity,
//! element size and byte total match the constants and types, and every row names a buffer
//! the code still has.

use std::collections::BTreeMap;
use std::mem::size_of;

use drivers::dynamixel::{MAX_PACKET_LEN, StatusDecoder};
use drivers::lds01::assembler::ASSEMBLER_REVOLUTIONS;
use drivers::lds01::decoder::DECODER_BUFFER_LEN;
use drivers::lds01::{Lds01Stream, READINGS_PER_REV, Reading, Revolution};
use firmware::runner::{METHOD_B_HISTORY, READ_CHUNK};
use perception::cloud::{CLOUD_CAPACITY, GlobalCloud};
use perception::dbscan::{Dbscan, GRID_CELLS, MAX_CLUSTERS};
use perception::doors::{Door, MAX_DOORS};
use perception::geometry::Point2;
use perception::method_a::{Candidate, MAX_CANDIDATES, MethodA};
use perception::walls::{BEARING_BINS, MAX_CORNERS, MAX_SEGMENTS, Segment, WallScratch};

/// (constant path as written in the table, capacity, element bytes), read from the code.
fn buffers_in_code() -> Vec<(&'static str, usize, usize)> {
    vec![
        (
            "drivers::lds01::decoder::DECODER_BUFFER_LEN",
            DECODER_BUFFER_LEN,
            1,
        ),
        (
            "drivers::lds01::assembler::ASSEMBLER_REVOLUTIONS",
            ASSEMBLER_REVOLUTIONS,
            size_of::<Revolution>(),
        ),
        (
            "drivers::lds01::READINGS_PER_REV",
            READINGS_PER_REV,
            size_of::<Reading>(),
        ),
        (
            "size_of::<drivers::lds01::Lds01Stream>()",
            1,
            size_of::<Lds01Stream>(),
        ),
        (
            "drivers::ldrobot::decoder::DECODER_BUFFER_LEN",
            drivers::ldrobot::decoder::DECODER_BUFFER_LEN,
            1,
        ),
        (
            "drivers::rplidar::decoder::DECODER_BUFFER_LEN",
            drivers::rplidar::decoder::DECODER_BUFFER_LEN,
            1,
        ),
        (
            "size_of::<drivers::ldrobot::LdrobotStream>()",
            1,
            size_of::<drivers::ldrobot::LdrobotStream>(),
        ),
        (
            "size_of::<drivers::rplidar::RplidarStream>()",
            1,
            size_of::<drivers::rplidar::RplidarStream>(),
        ),
        (
            "size_of::<drivers::lidar::AnyLidar>()",
            1,
            size_of::<drivers::lidar::AnyLidar>(),
        ),
        (
            "size_of::<drivers::lidar::detect::Detector>()",
            1,
            size_of::<drivers::lidar::detect::Detector>(),
        ),
        (
            "firmware::source::DETECT_BYTES",
            firmware::source::DETECT_BYTES,
            1,
        ),
        ("firmware::runner::READ_CHUNK", READ_CHUNK, 1),
        ("drivers::dynamixel::MAX_PACKET_LEN", MAX_PACKET_LEN, 1),
        (
            "size_of::<drivers::dynamixel::StatusDecoder>()",
            1,
            size_of::<StatusDecoder>(),
        ),
        (
            "perception::cloud::CLOUD_CAPACITY",
            CLOUD_CAPACITY,
            size_of::<Point2>(),
        ),
        (
            "size_of::<perception::cloud::GlobalCloud>()",
            1,
            size_of::<GlobalCloud>(),
        ),
        (
            "perception::dbscan::GRID_CELLS",
            GRID_CELLS + 1,
            size_of::<u16>(),
        ),
        (
            "perception::dbscan::MAX_CLUSTERS",
            MAX_CLUSTERS,
            size_of::<perception::dbscan::Cluster>(),
        ),
        (
            "size_of::<perception::dbscan::Dbscan>()",
            1,
            size_of::<Dbscan>(),
        ),
        (
            "perception::walls::BEARING_BINS",
            BEARING_BINS,
            size_of::<WallScratch>() / BEARING_BINS,
        ),
        (
            "perception::walls::MAX_SEGMENTS",
            MAX_SEGMENTS,
            size_of::<Segment>(),
        ),
        (
            "perception::walls::MAX_CORNERS",
            MAX_CORNERS,
            size_of::<Point2>(),
        ),
        ("perception::doors::MAX_DOORS", MAX_DOORS, size_of::<Door>()),
        (
            "perception::method_a::MAX_CANDIDATES",
            MAX_CANDIDATES,
            size_of::<Candidate>(),
        ),
        (
            "size_of::<perception::method_a::MethodA>()",
            1,
            size_of::<MethodA>(),
        ),
        (
            "perception::tracks::MAX_TRACKS",
            perception::tracks::MAX_TRACKS,
            size_of::<perception::tracks::Track>(),
        ),
        (
            "perception::tracks::OUTLINE_SLOTS",
            perception::tracks::OUTLINE_SLOTS,
            size_of::<(u32, perception::outline_average::AveragedOutline)>(),
        ),
        (
            "size_of::<perception::calibration::Calibration>()",
            1,
            size_of::<perception::calibration::Calibration>(),
        ),
        (
            "size_of::<perception::tracks::ReportModel>()",
            1,
            size_of::<perception::tracks::ReportModel>(),
        ),
        (
            "perception::tracks::MAX_PAIRS",
            perception::tracks::MAX_PAIRS,
            size_of::<(f32, u16, u16)>(),
        ),
        (
            "perception::tracks::MAX_TAKEN",
            perception::tracks::MAX_TAKEN,
            size_of::<(u16, u16)>(),
        ),
        (
            "perception::tracks::MAX_WALKERS",
            perception::tracks::MAX_WALKERS,
            size_of::<perception::tracks::Walker>(),
        ),
        (
            "perception::free_floor::COUNT_WORDS",
            perception::free_floor::COUNT_WORDS,
            size_of::<u32>(),
        ),
        (
            "perception::free_floor::WORDS",
            perception::free_floor::WORDS,
            size_of::<u32>(),
        ),
        (
            "perception::still_legs::MAX_SPOTS",
            perception::still_legs::MAX_SPOTS,
            size_of::<perception::still_legs::Spot>(),
        ),
        (
            "perception::legs::MAX_LEGS",
            perception::legs::MAX_LEGS,
            size_of::<Point2>(),
        ),
        (
            "perception::legs::MAX_PERSONS",
            perception::legs::MAX_PERSONS,
            size_of::<perception::legs::Person>(),
        ),
        (
            "perception::wall_map::MAX_MAP_WALLS",
            perception::wall_map::MAX_MAP_WALLS,
            size_of::<perception::wall_map::MapWall>(),
        ),
        (
            "size_of::<perception::scan_match::ScanMatcher>()",
            1,
            size_of::<perception::scan_match::ScanMatcher>(),
        ),
        (
            "perception::map_doors::MAX_DOORWAYS",
            perception::map_doors::MAX_DOORWAYS,
            size_of::<perception::geometry::Point2>(),
        ),
        (
            "perception::fusion::MAX_FRAME_OBJECTS",
            perception::fusion::MAX_FRAME_OBJECTS,
            size_of::<perception::fusion::FrameObject>(),
        ),
        (
            "firmware::runner::METHOD_B_HISTORY",
            METHOD_B_HISTORY,
            size_of::<[f32; perception::raster::SCAN_COLUMNS]>(),
        ),
        (
            "firmware::runner::B_WORKER_JOB_BYTES",
            1,
            firmware::runner::B_WORKER_JOB_BYTES,
        ),
        (
            "perception::raster::RASTER_LEN",
            perception::raster::RASTER_LEN,
            size_of::<f32>(),
        ),
        (
            "perception::yolo::LOGITS_LEN",
            perception::yolo::LOGITS_LEN,
            size_of::<f32>(),
        ),
        (
            "firmware::deadline::BUCKETS",
            firmware::deadline::BUCKETS,
            size_of::<u32>(),
        ),
        (
            "size_of::<firmware::deadline::DeadlineRecord>()",
            1,
            size_of::<firmware::deadline::DeadlineRecord>(),
        ),
        (
            "firmware::viz::VIZ_POOL",
            firmware::viz::VIZ_POOL,
            size_of::<firmware::viz::VizFrame>(),
        ),
        (
            "firmware::term_view::VIEW_POOL",
            firmware::term_view::VIEW_POOL,
            size_of::<firmware::term_view::ViewFrame>(),
        ),
        (
            "firmware::record_format::RECORD_RAW_BYTES",
            firmware::record_format::RECORD_RAW_BYTES,
            1,
        ),
        (
            "firmware::odom::JOURNAL_LEN",
            firmware::odom::JOURNAL_LEN,
            size_of::<firmware::odom::OdomRecord>(),
        ),
        (
            "firmware::reader::CHUNK_POOL",
            firmware::reader::CHUNK_POOL,
            size_of::<firmware::reader::Chunk>(),
        ),
        (
            "firmware::reader::DEVICE_QUEUE",
            firmware::reader::DEVICE_QUEUE,
            size_of::<firmware::reader::DeviceSample>(),
        ),
        (
            "firmware::odom::POSE_QUEUE",
            firmware::odom::POSE_QUEUE,
            size_of::<firmware::odom::OdomRecord>(),
        ),
        (
            "size_of::<firmware::reader::ClockMap>()",
            1,
            size_of::<firmware::reader::ClockMap>(),
        ),
        (
            "size_of::<perception::yolo::DecodeScratch>()",
            1,
            size_of::<perception::yolo::DecodeScratch>(),
        ),
        (
            "size_of::<firmware::runner::MethodBScratch>()",
            1,
            size_of::<firmware::runner::MethodBScratch>(),
        ),
        #[cfg(target_arch = "x86_64")]
        (
            "models::int8_kernel::TILE_LEN",
            models::int8_kernel::TILE_LEN,
            size_of::<i32>(),
        ),
        #[cfg(target_arch = "x86_64")]
        (
            "models::int8_kernel::MAX_SPECS",
            models::int8_kernel::MAX_SPECS,
            models::int8_kernel::SPEC_BYTES,
        ),
        (
            "perception::yolo::MAX_DETECTIONS",
            perception::yolo::MAX_DETECTIONS,
            size_of::<perception::yolo::Detection>(),
        ),
    ]
}

/// Rows of the table: constant → (capacity, element bytes, bytes).
fn rows_in_doc() -> BTreeMap<String, (usize, usize, usize)> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../memory-budget.md");
    let text = std::fs::read_to_string(path).expect("memory-budget.md at the repository root");
    let mut rows = BTreeMap::new();
    for line in text.lines().filter(|l| l.starts_with('|')) {
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        if cells.len() < 6 || !cells[1].starts_with('`') {
            continue; // header, separator, or a row without a constant
        }
        let num = |s: &str| s.replace([',', ' '], "").parse::<usize>();
        let (Ok(cap), Ok(elem), Ok(bytes)) = (num(cells[2]), num(cells[3]), num(cells[4])) else {
            panic!("memory-budget.md: unreadable numbers in row: {line}");
        };
        rows.insert(cells[1].trim_matches('`').to_owned(), (cap, elem, bytes));
    }
    rows
}

#[test]
fn memory_budget_matches_code() {
    let doc = rows_in_doc();
    let code = buffers_in_code();
    for (name, cap, elem) in &code {
        let Some(&(dcap, delem, dbytes)) = doc.get(*name) else {
            panic!("memory-budget.md has no row for `{name}` (capacity {cap}, element {elem} B)");
        };
        assert_eq!(
            (dcap, delem),
            (*cap, *elem),
            "row `{name}`: capacity/element size"
        );
        assert_eq!(
            dbytes,
            cap * elem,
            "row `{name}`: bytes ≠ capacity × element"
        );
    }
    for name in doc.keys() {
        if cfg!(not(target_arch = "x86_64")) && name.starts_with("models::int8_kernel::") {
            continue; // an x86-64 kernel's buffers: not in this build
        }
        assert!(
            code.iter().any(|(n, ..)| n == name),
            "memory-budget.md row `{name}` names no buffer the test knows; add it to buffers_in_code()"
        );
    }
}

#[test]
fn print_sizes() {
    for (name, cap, elem) in buffers_in_code() {
        println!("{name}: {cap} × {elem} B = {} B", cap * elem);
    }
}
