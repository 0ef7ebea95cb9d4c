//! The committed forest tables are exactly what the committed training data produce.

use models::train::{TrainConfig, emit_rust, read_csv, train};

#[test]
fn committed_tables_match_committed_data() {
    let data = include_str!("../../models/data/forest-train.csv");
    let tables = include_str!("../../models/src/forest_tables.rs");
    let object = models::forest::forest().object_frame;
    let d = read_csv(data, object).expect("training data parses");
    let t = train(
        &d,
        &TrainConfig {
            object_frame: object,
            ..TrainConfig::default()
        },
    );
    let how = tables
        .lines()
        .find_map(|l| l.strip_prefix("//! Regenerate with `"))
        .and_then(|l| l.strip_suffix("`."))
        .expect("the tables say how to regenerate them");
    assert!(
        emit_rust(&t, how) == tables,
        "models/src/forest_tables.rs differs from what models/data/forest-train.csv trains; \
         regenerate with `{how}`"
    );
}

#[test]
fn compiled_forest_agrees_with_its_training_data() {
    // Training accuracy of the compiled tables: far above chance, and the same call path the
    // runtime uses.
    let data = include_str!("../../models/data/forest-train.csv");
    let f = models::forest::forest();
    let d = read_csv(data, f.object_frame).expect("training data parses");
    let right =
        d.x.iter()
            .zip(&d.y)
            .filter(|(x, y)| f.predict(x).0 == **y as usize)
            .count();
    let share = right as f64 / d.x.len() as f64;
    assert!(share > 0.85, "training accuracy {share}");
}
