// Present so that Cargo resolves this crate's build-dependencies (syn's features for the proc
// macros); it does nothing.
fn main() {}
