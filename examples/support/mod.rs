//! Shared by the examples: command-line options, progress on long runs,
//! and two-panel SVG plots (the motion above, the constraint residual below).
#![allow(dead_code)] // each example uses its own subset

use plotters::prelude::*;
use std::path::PathBuf;

/// `--duration SECONDS` (simulated time), `--progress` (report on stderr),
/// `--out DIR` (where the SVG goes; `plots` in cargo's target directory by
/// default).
pub struct Options {
    /// Simulated time, s.
    pub duration: f64,
    /// Whether to print progress.
    pub progress: bool,
    /// Output folder.
    pub out_dir: PathBuf,
}

impl Options {
    /// Parses the command line; `duration` is the default simulated time,
    /// short enough that the example finishes in seconds.
    pub fn parse(duration: f64) -> Options {
        let mut options = Options {
            duration,
            progress: false,
            out_dir: target_dir().join("plots"),
        };
        let mut args = std::env::args().skip(1);
        while let Some(arg) = args.next() {
            match arg.as_str() {
                "--duration" => {
                    options.duration = args
                        .next()
                        .and_then(|v| v.parse().ok())
                        .filter(|d: &f64| *d > 0.0)
                        .unwrap_or_else(|| usage("--duration takes a positive number of seconds"));
                }
                "--progress" => options.progress = true,
                "--out" => {
                    options.out_dir = args
                        .next()
                        .map(PathBuf::from)
                        .unwrap_or_else(|| usage("--out takes a folder"))
                }
                "--help" | "-h" => usage(""),
                other => usage(&format!("unknown argument `{other}`")),
            }
        }
        options
    }

    /// The path of this example's plot, its folder created.
    pub fn plot_path(&self, name: &str) -> PathBuf {
        std::fs::create_dir_all(&self.out_dir)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", self.out_dir.display()));
        self.out_dir.join(format!("{name}.svg"))
    }

    /// A progress reporter over `[0, duration]`, silent unless `--progress`.
    pub fn progress(&self) -> Progress {
        Progress {
            enabled: self.progress,
            duration: self.duration,
            next: 0.1,
            started: std::time::Instant::now(),
        }
    }
}

/// Cargo's target directory: `CARGO_TARGET_DIR` when set, else the one
/// this example was built in (`<target>/<profile>/examples/<name>`), else
/// `target`. Outputs never land in the clone's `target/` when the build
/// went elsewhere.
fn target_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CARGO_TARGET_DIR") {
        return PathBuf::from(dir);
    }
    let exe = std::env::current_exe().ok();
    let built_in = exe.as_deref().and_then(|exe| {
        let examples = exe.parent()?;
        (examples.file_name()? == "examples").then_some(examples.parent()?.parent()?)
    });
    built_in.map_or_else(|| PathBuf::from("target"), PathBuf::from)
}

fn usage(problem: &str) -> ! {
    if !problem.is_empty() {
        eprintln!("error: {problem}");
    }
    eprintln!("usage: cargo run --release --example NAME -- [--duration SECONDS] [--progress] [--out DIR]");
    std::process::exit(2)
}

/// Prints simulated time and wall time at every 10% of the run.
pub struct Progress {
    enabled: bool,
    duration: f64,
    next: f64,
    started: std::time::Instant,
}

impl Progress {
    /// Call with the current simulated time.
    pub fn tick(&mut self, t: f64) {
        if self.enabled && t >= self.next * self.duration {
            eprintln!(
                "  {:>3.0}%  t = {t:.3} s  ({:.1} s wall)",
                100.0 * self.next,
                self.started.elapsed().as_secs_f64()
            );
            self.next += 0.1;
        }
    }
}

/// One curve.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// A curve from its label and points.
    pub fn new(label: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.to_string(),
            points,
        }
    }
}

/// One panel of a figure.
pub struct Panel {
    /// Panel caption.
    pub title: String,
    /// Axis labels.
    pub x_label: String,
    /// Axis labels.
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
    /// Logarithmic y axis (for residuals and separations).
    pub log_y: bool,
    /// Same scale on both axes (for paths in the plane).
    pub equal_axes: bool,
}

impl Panel {
    /// A panel with linear axes.
    pub fn new(title: &str, x_label: &str, y_label: &str, series: Vec<Series>) -> Panel {
        Panel {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            series,
            log_y: false,
            equal_axes: false,
        }
    }

    /// The same with a logarithmic y axis.
    pub fn log(mut self) -> Panel {
        self.log_y = true;
        self
    }

    /// The same with equal scales on both axes.
    pub fn equal(mut self) -> Panel {
        self.equal_axes = true;
        self
    }
}

/// Draws the panels stacked vertically into an SVG at `path`.
pub fn plot(
    path: &std::path::Path,
    title: &str,
    panels: &[Panel],
) -> Result<(), Box<dyn std::error::Error>> {
    let height = 60 + 340 * panels.len() as u32;
    let root = SVGBackend::new(path, (820, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let areas = root.split_evenly((panels.len(), 1));
    for (panel, area) in panels.iter().zip(areas.iter()) {
        draw_panel(area, panel)?;
    }
    root.present()?;
    Ok(())
}

fn draw_panel(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    panel: &Panel,
) -> Result<(), Box<dyn std::error::Error>> {
    let points = panel.series.iter().flat_map(|s| s.points.iter());
    let floor = 1e-18;
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in points {
        let y = if panel.log_y { y.abs().max(floor) } else { y };
        if x.is_finite() && y.is_finite() {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
    }
    if !x0.is_finite() || !y0.is_finite() {
        // No finite point at all: an empty unit frame.
        (x0, x1, y0, y1) = (0.0, 1.0, if panel.log_y { 1e-3 } else { 0.0 }, 1.0);
    }
    // A degenerate range (a single value).
    if x0.partial_cmp(&x1) != Some(std::cmp::Ordering::Less) {
        (x0, x1) = (x0 - 1.0, x0 + 1.0);
    }
    if y0.partial_cmp(&y1) != Some(std::cmp::Ordering::Less) {
        (y0, y1) = if panel.log_y {
            (y0 / 10.0, y0 * 10.0)
        } else {
            (y0 - 1.0, y0 + 1.0)
        };
    }
    if panel.equal_axes {
        // Widen the narrower range so one unit is as long on both axes
        // (the panel is about 760 × 290 pixels of plot).
        let (w, h) = (x1 - x0, y1 - y0);
        let aspect = 760.0 / 290.0;
        if w / h < aspect {
            let extra = (h * aspect - w) / 2.0;
            (x0, x1) = (x0 - extra, x1 + extra);
        } else {
            let extra = (w / aspect - h) / 2.0;
            (y0, y1) = (y0 - extra, y1 + extra);
        }
    }
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
    ];
    if panel.log_y {
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, (y0 / 2.0..y1 * 2.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(&panel.x_label)
            .y_desc(&panel.y_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        for (series, colour) in panel.series.iter().zip(colours.iter().cycle()) {
            let colour = *colour;
            chart
                .draw_series(LineSeries::new(
                    series.points.iter().map(|&(x, y)| (x, y.abs().max(floor))),
                    colour.stroke_width(2),
                ))?
                .label(&series.label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    } else {
        let pad = 0.05 * (y1 - y0);
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, y0 - pad..y1 + pad)?;
        chart
            .configure_mesh()
            .x_desc(&panel.x_label)
            .y_desc(&panel.y_label)
            .draw()?;
        for (series, colour) in panel.series.iter().zip(colours.iter().cycle()) {
            let colour = *colour;
            chart
                .draw_series(LineSeries::new(
                    series.points.iter().copied(),
                    colour.stroke_width(2),
                ))?
                .label(&series.label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}
