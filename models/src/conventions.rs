//! What a Method B model says about the images it was trained on: where the raster's first
//! column was (`perception::seam`) and whether its labels were drawn where the sweep read
//! each bearing (`perception::sweep`). A model is only right when the runtime draws its
//! images and places its boxes the same way, so the file carries both, as ONNX
//! `metadata_props` written by `training/export.py`:
//!
//! | key | values | absent |
//! |---|---|---|
//! | [`SEAM_KEY`] `umbra.seam` | `fixed`, `quiet` | not declared |
//! | [`DESKEW_KEY`] `umbra.deskew` | `true`, `false` | not declared |
//!
//! The runtime follows what the file declares unless its configuration says otherwise
//! (`[method_b] seam`, `deskew`); a file that declares nothing (models exported before these
//! keys, other exporters' files) is read as bin 0 first and the middle's pose, as before. A
//! value this runtime does not know is an error naming the key, not a guess: a model drawn
//! another way would be read wrong without a sign. `no_std`, parsing only.

use perception::seam::SeamRule;

/// The metadata key naming the seam rule the training images were drawn with.
pub const SEAM_KEY: &str = "umbra.seam";
/// The metadata key saying whether the training labels were swept (`umbra-sim dataset
/// --deskew`).
pub const DESKEW_KEY: &str = "umbra.deskew";

/// The conventions a model file declares; `None` where it declares nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Conventions {
    /// Where the training images' first column was.
    pub seam: Option<SeamRule>,
    /// Whether the training labels were drawn where the sweep read them.
    pub deskew: Option<bool>,
}

/// A declared value this runtime does not understand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownConvention<'a> {
    /// The key.
    pub key: &'a str,
    /// What the file gave.
    pub value: &'a str,
}

impl core::fmt::Display for UnknownConvention<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let known = if self.key == SEAM_KEY {
            "\"fixed\" or \"quiet\""
        } else {
            "\"true\" or \"false\""
        };
        write!(
            f,
            "metadata {} = {:?}: this runtime knows {known}",
            self.key, self.value
        )
    }
}

impl Conventions {
    /// Reads the conventions from a model's metadata entries (key, value); other keys (the
    /// exporter's own: names, stride, …) are ignored.
    pub fn from_metadata<'a>(
        entries: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Result<Self, UnknownConvention<'a>> {
        let mut c = Conventions::default();
        for (key, value) in entries {
            let bad = UnknownConvention { key, value };
            match key {
                SEAM_KEY => {
                    let v = value.trim();
                    c.seam = Some(
                        [SeamRule::Fixed, SeamRule::Quiet]
                            .into_iter()
                            .find(|r| r.name() == v)
                            .ok_or(bad)?,
                    )
                }
                DESKEW_KEY => {
                    c.deskew = Some(match value.trim() {
                        "true" => true,
                        "false" => false,
                        _ => return Err(bad),
                    })
                }
                _ => {}
            }
        }
        Ok(c)
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_file_declaring_nothing_declares_nothing() {
        let c = Conventions::from_metadata([("names", "{0: 'chair'}"), ("stride", "32")]);
        assert_eq!(c, Ok(Conventions::default()));
    }

    #[test]
    fn both_keys_are_read() {
        let c = Conventions::from_metadata([(SEAM_KEY, "quiet"), (DESKEW_KEY, "true")]).unwrap();
        assert_eq!(c.seam, Some(SeamRule::Quiet));
        assert_eq!(c.deskew, Some(true));
        let c = Conventions::from_metadata([(SEAM_KEY, "fixed"), (DESKEW_KEY, "false")]).unwrap();
        assert_eq!((c.seam, c.deskew), (Some(SeamRule::Fixed), Some(false)));
    }

    #[test]
    fn an_unknown_value_is_an_error_naming_its_key() {
        let e = Conventions::from_metadata([(SEAM_KEY, "emptiest")]).unwrap_err();
        assert_eq!(e.key, SEAM_KEY);
        assert_eq!(
            e.to_string(),
            "metadata umbra.seam = \"emptiest\": this runtime knows \"fixed\" or \"quiet\""
        );
        let e = Conventions::from_metadata([(DESKEW_KEY, "1")]).unwrap_err();
        assert_eq!(e.key, DESKEW_KEY);
    }
}
