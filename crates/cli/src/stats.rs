//! The `--stats` printout: time per stage, rays by kind, peak memory and the BVH's figures.

use std::fmt::Write as _;
use std::time::Duration;

use glint_render::{BuildPhases, IntegratorKind, RenderSettings, RenderStats, Scene};

use crate::report::plural;

/// The `--stats` printout: named sections of labelled values, printed in the order they were
/// added. Each part of the program adds its own section (times, rays, memory, the ray
/// engine's figures), so one can be added without touching the others.
#[derive(Debug, Default)]
pub struct Stats {
    sections: Vec<(String, Vec<(String, String)>)>,
}

impl Stats {
    /// Adds a section and returns it to fill with `row`.
    pub fn section(&mut self, title: &str) -> Section<'_> {
        self.sections.push((title.to_string(), Vec::new()));
        let rows = &mut self.sections.last_mut().expect("just pushed").1;
        Section { rows }
    }

    /// The printout: `stats:`, then per section its title and indented, aligned rows.
    pub fn render(&self) -> String {
        let width = self
            .sections
            .iter()
            .flat_map(|(_, rows)| rows.iter().map(|(label, _)| label.len()))
            .max()
            .unwrap_or(0);
        let mut text = String::from("stats:\n");
        for (title, rows) in &self.sections {
            let _ = writeln!(text, "  {title}");
            for (label, value) in rows {
                let _ = writeln!(text, "    {label:<width$}  {value}");
            }
        }
        text
    }
}

/// One section of `Stats`.
#[derive(Debug)]
pub struct Section<'a> {
    rows: &'a mut Vec<(String, String)>,
}

impl Section<'_> {
    pub fn row(&mut self, label: &str, value: impl std::fmt::Display) -> &mut Self {
        self.rows.push((label.to_string(), value.to_string()));
        self
    }
}

/// The process's peak resident memory in bytes (Linux: `VmHWM` in /proc/self/status).
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kib: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024)
}

/// `1.234 s`
pub fn seconds(duration: Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

/// Rays by kind: every sample of every rendered pixel starts with one camera ray, and the
/// course family traces one more per sample for the feature layers; the rest are the
/// secondary (reflection, refraction, bounce) and shadow rays.
pub fn rays_section(report: &mut Stats, settings: &RenderSettings, stats: &RenderStats) {
    let bounds = settings.bounds();
    let camera = u64::from(bounds.width())
        * u64::from(bounds.height())
        * u64::from(settings.samples().len() as u32);
    let features = if settings.features && settings.integrator != IntegratorKind::Path {
        camera
    } else {
        0
    };
    let mut section = report.section("rays");
    section.row("camera", camera);
    if features > 0 {
        section.row("feature layers", features);
    }
    section
        .row(
            "secondary and shadow",
            stats.rays.saturating_sub(camera + features),
        )
        .row("total", stats.rays);
}

/// `--stats`' BVH figures: how the split method shaped the tree, where the build's time went
/// and what the tree costs the camera rays (measured in a separate counting pass, so the render
/// itself counted nothing). `build_time` is the `build` stage of the time section: the one
/// build figure, which the phases are printed as parts of.
pub fn bvh_stats(scene: &Scene, settings: &RenderSettings, build_time: Duration) -> String {
    let bvh = scene.bvh_stats();
    let walk = glint_render::measure_traversal(scene, settings);
    format!(
        "BVH ({}): {} tree{}, {} nodes, {} leaves, depth {}, SAH cost {:.2}\n{}\
         BVH traversal: {:.2} nodes and {:.2} triangle blocks per camera ray ({} rays through \
         pixel centres, {:.0}% hit)\n",
        bvh.split.name(),
        bvh.trees,
        plural(bvh.trees as u64),
        bvh.nodes,
        bvh.leaves,
        bvh.depth,
        bvh.sah_cost,
        build_parts(build_time, bvh.largest),
        walk.nodes_per_ray(),
        walk.blocks_per_ray(),
        walk.rays,
        100.0 * walk.hits as f64 / walk.rays.max(1) as f64,
    )
}

/// The build stage's time in parts that add up to it, in tenths of a millisecond so that the
/// printed figures add up exactly: the largest tree's phases (its root node's splits run
/// before any subtree can run apart, so they are what more threads shorten least), and the
/// rest (the other trees, the top level, moving the scene into place).
fn build_parts(build_time: Duration, largest: Option<(usize, BuildPhases)>) -> String {
    let tenths = |d: Duration| (d.as_secs_f64() * 1e4).round() as u64;
    let ms = |tenths: u64| format!("{}.{} ms", tenths / 10, tenths % 10);
    let total = tenths(build_time);
    let Some((primitives, p)) = largest else {
        return format!("BVH build: {}, no wide tree\n", ms(total));
    };
    let phases = [
        ("boxes", tenths(p.boxes)),
        ("root splits", tenths(p.top_splits)),
        ("subtrees", tenths(p.subtrees)),
        ("blocks", tenths(p.pack)),
    ];
    let largest: u64 = phases.iter().map(|(_, t)| t).sum();
    // The phases are timed inside the stage, so they fit in it; rounding could only tip a
    // stage of nothing but the one tree by a tenth, which the total absorbs.
    let total = total.max(largest);
    let listed: Vec<String> = phases
        .iter()
        .map(|(name, t)| format!("{name} {}", ms(*t)))
        .collect();
    format!(
        "BVH build: {} = largest tree ({primitives} primitives) {} ({}) + the rest {}\n",
        ms(total),
        ms(largest),
        listed.join(" + "),
        ms(total - largest),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_sections_print_in_order_and_align() {
        let mut stats = Stats::default();
        stats
            .section("time")
            .row("load", "0.1 s")
            .row("render", "2 s");
        stats.section("memory").row("peak resident", "12 MiB");
        assert_eq!(
            stats.render(),
            "stats:\n  time\n    load           0.1 s\n    render         2 s\n  memory\n    \
             peak resident  12 MiB\n"
        );
    }

    /// The parts are rounded first and the rest is what they leave, so the printed figures add
    /// up to the one build figure.
    #[test]
    fn the_build_parts_add_up_to_the_build() {
        let us = Duration::from_micros;
        let phases = BuildPhases {
            boxes: us(1_040),
            top_splits: us(2_960),
            subtrees: us(3_060),
            pack: us(990),
        };
        assert_eq!(
            build_parts(us(10_040), Some((1000, phases))),
            "BVH build: 10.0 ms = largest tree (1000 primitives) 8.1 ms (boxes 1.0 ms + root \
             splits 3.0 ms + subtrees 3.1 ms + blocks 1.0 ms) + the rest 1.9 ms\n"
        );
        assert_eq!(
            build_parts(us(240), None),
            "BVH build: 0.2 ms, no wide tree\n"
        );
    }

    #[test]
    fn peak_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(peak_rss().is_some_and(|bytes| bytes > 0));
        }
    }
}
