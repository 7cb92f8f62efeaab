//! The processor features the build assumes (`.cargo/config.toml` compiles
//! for x86-64-v2), checked first thing in both binaries so that an older
//! processor gets a sentence instead of an illegal-instruction crash.

/// `Err` with what is missing when this processor cannot run the build.
pub fn check() -> Result<(), String> {
    #[cfg(target_arch = "x86_64")]
    {
        let missing: Vec<&str> = [
            ("sse3", std::is_x86_feature_detected!("sse3")),
            ("ssse3", std::is_x86_feature_detected!("ssse3")),
            ("sse4.1", std::is_x86_feature_detected!("sse4.1")),
            ("sse4.2", std::is_x86_feature_detected!("sse4.2")),
            ("popcnt", std::is_x86_feature_detected!("popcnt")),
            ("cmpxchg16b", std::is_x86_feature_detected!("cmpxchg16b")),
        ]
        .into_iter()
        .filter(|(_, present)| !present)
        .map(|(name, _)| name)
        .collect();
        if !missing.is_empty() {
            return Err(format!(
                "this build of Volcad Studio needs an x86-64-v2 processor (2009 or later); this one lacks {}. Build from source without `.cargo/config.toml`'s target-cpu line to run here",
                missing.join(", ")
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// The machines that build and test the project are x86-64-v2 or
    /// newer (or not x86-64 at all), so the check passes here.
    #[test]
    fn this_processor_runs_the_build() {
        assert_eq!(super::check(), Ok(()));
    }
}
