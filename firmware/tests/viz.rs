//! Recording, live view and snapshot, end to end through the `umbra` binary: the MCAP file
//! reads back with the `mcap` crate (channels, Foxglove schemas, one scan a frame), a
//! WebSocket client speaking Foxglove's protocol sees the channels and receives frames, and
//! the snapshot is an SVG with the map's layers.
#![cfg(feature = "viz")]

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("umbra-viz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn record_writes_an_mcap_that_reads_back_and_a_snapshot() {
    let rec = tmp("run.mcap");
    let svg = tmp("map.svg");
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args([
            "run", "--frames", "12", "--speed", "max", "--quiet", "--record",
        ])
        .arg(&rec)
        .arg("--snapshot")
        .arg(&svg)
        .env("RUST_LOG", "warn")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&rec).unwrap();
    let mut per_topic: BTreeMap<String, usize> = BTreeMap::new();
    let mut schemas: BTreeMap<String, String> = BTreeMap::new();
    let mut raw_meta = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).expect("an MCAP file") {
        let m = m.expect("a readable message");
        *per_topic.entry(m.channel.topic.clone()).or_default() += 1;
        let schema = m
            .channel
            .schema
            .as_ref()
            .map_or("(none)".to_owned(), |s| s.name.clone());
        schemas.insert(m.channel.topic.clone(), schema);
        if m.channel.topic == "/umbra/lidar_raw" {
            assert_eq!(m.channel.message_encoding, "application/octet-stream");
            raw_meta = m.channel.metadata.clone();
        }
        assert!(!m.data.is_empty());
    }
    let want: BTreeMap<String, String> = [
        ("/scan", "foxglove.LaserScan"),
        ("/tf", "foxglove.FrameTransforms"),
        ("/pose", "foxglove.PoseInFrame"),
        ("/perception", "foxglove.SceneUpdate"),
        ("/umbra/lidar_raw", "(none)"),
        ("/umbra/odometry", "umbra.Odometry"),
    ]
    .into_iter()
    .map(|(a, b)| (a.to_owned(), b.to_owned()))
    .collect();
    assert_eq!(schemas, want);
    for topic in ["/scan", "/tf", "/pose", "/perception", "/umbra/lidar_raw"] {
        assert_eq!(per_topic[topic], 12, "{topic}: one message a frame");
    }
    // The simulator's encoders and compass at 20 Hz: ~4 samples a 0.2 s frame.
    assert!(per_topic["/umbra/odometry"] >= 40, "{per_topic:?}");
    assert_eq!(raw_meta.get("model").map(String::as_str), Some("lds01"));
    assert!(raw_meta.contains_key("compass_calibration"));
    let s = std::fs::read_to_string(&svg).unwrap();
    assert!(s.starts_with("<svg"));
    for id in ["cloud", "walls", "objects", "robot"] {
        assert!(s.contains(&format!("id=\"{id}\"")), "{id}");
    }
    assert!(s.matches("<circle").count() > 100, "the cloud is drawn");
}

#[test]
fn a_live_client_sees_the_channels_and_receives_frames() {
    // The server binds port 0 and says which port it got: no port is chosen here and then
    // raced for, and the client retries its handshake until the server answers (or 30 s).
    let mut child = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(["run", "--frames", "40", "--quiet", "--live", "127.0.0.1:0"])
        .env("RUST_LOG", "warn")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        use std::io::BufRead as _;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            if let Some(rest) = line.strip_prefix("umbra: live view on ws://127.0.0.1:") {
                let port: u16 = rest.split_whitespace().next().unwrap().parse().unwrap();
                let _ = tx.send(port);
            }
        }
    });
    let port = rx
        .recv_timeout(Duration::from_secs(60))
        .expect("umbra says the port its live server bound");
    let start = Instant::now();
    let mut ws = loop {
        let mut req = tungstenite::client::IntoClientRequest::into_client_request(format!(
            "ws://127.0.0.1:{port}"
        ))
        .unwrap();
        req.headers_mut()
            .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
        let attempt = std::net::TcpStream::connect(("127.0.0.1", port))
            .map_err(|e| e.to_string())
            .and_then(|tcp| {
                tcp.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
                tungstenite::client(req, tcp).map_err(|e| format!("handshake: {e}"))
            });
        match attempt {
            Ok((ws, _)) => break ws,
            Err(_) if start.elapsed() < Duration::from_secs(30) => {
                std::thread::sleep(Duration::from_millis(50))
            }
            Err(e) => panic!("no live server on {port}: {e}"),
        }
    };
    let mut topics: BTreeMap<String, u64> = BTreeMap::new();
    let mut subscribed = false;
    let mut binary = 0;
    while binary < 3 {
        let msg = ws.read().expect("a message from the server");
        match msg {
            tungstenite::Message::Text(t) => {
                let v: serde_json::Value = serde_json::from_str(&t).unwrap();
                if v["op"] == "advertise" {
                    for c in v["channels"].as_array().unwrap() {
                        topics.insert(
                            c["topic"].as_str().unwrap().to_owned(),
                            c["id"].as_u64().unwrap(),
                        );
                    }
                }
                if !subscribed && topics.contains_key("/scan") {
                    let sub = serde_json::json!({"op": "subscribe", "subscriptions":
                        [{"id": 1, "channelId": topics["/scan"]}]});
                    ws.send(tungstenite::Message::Text(sub.to_string().into()))
                        .unwrap();
                    subscribed = true;
                }
            }
            tungstenite::Message::Binary(b) => {
                assert_eq!(b[0], 1, "a messageData frame");
                binary += 1;
            }
            _ => {}
        }
    }
    let seen: BTreeSet<&str> = topics.keys().map(String::as_str).collect();
    assert!(
        ["/scan", "/tf", "/pose", "/perception"]
            .iter()
            .all(|t| seen.contains(t)),
        "{seen:?}"
    );
    drop(ws);
    let status = child.wait().unwrap();
    assert!(status.success());
}
