//! What `glint bench`, the criterion benches and glint-io's tests of the ray engine need beyond
//! the API, behind the `bench` cargo feature: the fixed ray workloads (`workload`).

pub mod workload;
