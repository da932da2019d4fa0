//! The command line's optional parts, left out of the default build because the main job
//! (`tendril reproduce`) never uses them and they cost a large share of a fresh build
//! (docs/guide/install.md, "What a build costs"). A command that needs a part this build left
//! out fails at once, before any work, with the command that builds it.

/// An optional part of the command line: a Cargo feature of the `tendril` package.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// `tendril view`: MuJoCo's interactive viewer (winit, egui and their window-system clients).
    Viewer,
    /// `tendril render` and `tendril run --video`: H.264 in MP4 (OpenH264, built from C).
    Video,
}

impl Feature {
    /// The Cargo feature's name.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Viewer => "viewer",
            Feature::Video => "video",
        }
    }

    /// Whether this build has it.
    pub fn built(self) -> bool {
        match self {
            Feature::Viewer => cfg!(feature = "viewer"),
            Feature::Video => cfg!(feature = "video"),
        }
    }

    /// `Ok` when this build has the part; otherwise the error `what` (the command asking for it)
    /// reports: what is missing and the command that builds it.
    pub fn require(self, what: &str) -> anyhow::Result<()> {
        if self.built() { Ok(()) } else { Err(self.missing(what)) }
    }

    /// The error `what` (the command asking for this part) reports when the build lacks it.
    pub fn missing(self, what: &str) -> anyhow::Error {
        anyhow::anyhow!(missing_text(self, what))
    }
}

/// What `what` says when `feature` is missing.
fn missing_text(feature: Feature, what: &str) -> String {
    let name = feature.name();
    format!(
        "{what} needs the `{name}` feature, which this build of tendril leaves out; from the checkout, \
         build and install it with: cargo install --path . --locked --features {name}"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_part_names_its_feature_and_the_command_that_builds_it() {
        let text = missing_text(Feature::Video, "tendril render");
        assert!(text.starts_with("tendril render needs the `video` feature"), "{text}");
        assert!(text.ends_with("cargo install --path . --locked --features video"), "{text}");
        for f in [Feature::Viewer, Feature::Video] {
            assert_eq!(f.require("x").is_ok(), f.built());
        }
    }
}
