//! Hashes the compiled-in YOLO models (SHA-256) so that a binary can say which model it
//! carries (`umbra --version`): `UMBRA_MODEL_SHA256` and `UMBRA_MODEL_INT8_SHA256`.

use sha2::{Digest, Sha256};

fn main() {
    for (file, var) in [
        ("yolo/umbra-yolov8n.onnx", "UMBRA_MODEL_SHA256"),
        ("yolo/umbra-yolov8n-int8.onnx", "UMBRA_MODEL_INT8_SHA256"),
    ] {
        println!("cargo:rerun-if-changed={file}");
        let hex = match std::fs::read(file) {
            Ok(bytes) => Sha256::digest(&bytes)
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect::<String>(),
            Err(e) => panic!("{file}: {e}"),
        };
        println!("cargo:rustc-env={var}={hex}");
    }
}
