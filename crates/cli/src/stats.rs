//! The `--stats` printout: time per stage, rays by kind, peak memory and the BVH's figures.

use std::fmt::Write as _;
use std::time::Duration;

use glint_render::{IntegratorKind, RenderSettings, RenderStats, Scene};

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

/// `--stats`' BVH figures: how the split method shaped the tree and what it costs the camera
/// rays (measured in a separate counting pass, so the render itself counted nothing).
pub fn bvh_stats(scene: &Scene, settings: &RenderSettings) -> String {
    let bvh = scene.bvh_stats();
    let walk = glint_render::measure_traversal(scene, settings);
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    // Where the largest tree's build spent its time: the root node's splits run before any
    // subtree can run apart, so they are what more threads shorten least.
    let phases = bvh.largest.map_or_else(String::new, |(primitives, p)| {
        format!(
            "BVH build phases, largest tree ({primitives} primitives): boxes {:.1} ms, root \
             splits {:.1} ms, subtrees {:.1} ms, blocks {:.1} ms\n",
            ms(p.boxes),
            ms(p.top_splits),
            ms(p.subtrees),
            ms(p.pack),
        )
    });
    format!(
        "BVH ({}): built in {:.1} ms; {} tree{}, {} nodes, {} leaves, depth {}, SAH cost {:.2}\n\
         {phases}\
         BVH traversal: {:.2} nodes and {:.2} triangle blocks per camera ray ({} rays through \
         pixel centres, {:.0}% hit)\n",
        bvh.split.name(),
        ms(bvh.build_time),
        bvh.trees,
        plural(bvh.trees as u64),
        bvh.nodes,
        bvh.leaves,
        bvh.depth,
        bvh.sah_cost,
        walk.nodes_per_ray(),
        walk.blocks_per_ray(),
        walk.rays,
        100.0 * walk.hits as f64 / walk.rays.max(1) as f64,
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

    #[test]
    fn peak_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(peak_rss().is_some_and(|bytes| bytes > 0));
        }
    }
}
