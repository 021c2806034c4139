//! AFL++ fuzz target `material` (see src/targets.rs and docs/fuzzing.md).
fn main() {
    afl::fuzz!(|data: &[u8]| relume_fuzz::targets::material(data));
}
