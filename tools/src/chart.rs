//! A benchmark CSV as a PNG chart (`vkhair plot`, and `vkhair bench` for the
//! charts it writes beside its CSVs).
//!
//! - `render.csv` (benches/render.rs): GPU ms per frame against camera distance,
//!   one line per resolution, and the drawn segment count.
//! - `volume.csv` (benches/volume.rs): GPU ms per simulation step against the
//!   grid resolution, one line per solver, and PCG iterations per step.
//! - `scaling.csv` (`vkhair bench`): GPU and CPU-reference ms against the work
//!   (particles, cells, pixels), one panel per scaling axis.
//! - `transparency.csv` (`vkhair bench`): each transparency mode's GPU ms per
//!   frame and memory against its error from the exact reference, one series
//!   per scene, each point labelled with its mode.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Where Debian's fonts-dejavu-core puts the font the chart is labelled with.
const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

use crate::output::{write_png, Error};
use crate::say;

type Lines = BTreeMap<String, Vec<(f64, f64)>>;

/// The most `plot` reads of a CSV unless `VKHAIR_MAX_INPUT_BYTES` says
/// otherwise: 64 MiB (the benchmarks write a few KiB).
const MAX_CSV_BYTES: u64 = 64 << 20;

/// Rows left out of a chart that are named one by one; beyond, a count.
const NAMED_ROWS: usize = 5;

/// Chart size, pixels.
const SIZE: (u32, u32) = (1100, 500);

/// Largest magnitude a plotted value may have: beyond it a benchmark figure is
/// garbage (and would stall the axis layout).
const LARGEST_VALUE: f64 = 1e12;

/// The CSV's header and rows of numbers (text cells kept as they are).
struct Table {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn read(path: &Path) -> Result<Self, Error> {
        let cap = vkhair::files::input_cap(MAX_CSV_BYTES)?;
        let bytes = vkhair::files::read_capped(path, cap, "a benchmark CSV").map_err(|e| match e {
            vkhair::Error::Io { source, .. } => format!("cannot read {}: {source}", path.display()).into(),
            e => Error::from(e),
        })?;
        let text =
            String::from_utf8(bytes).map_err(|_| format!("{} is not UTF-8 text (a CSV is text)", path.display()))?;
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header = lines
            .next()
            .ok_or_else(|| format!("{} is empty: a benchmark CSV starts with a header line", path.display()))?
            .split(',')
            .map(|h| h.trim().to_owned())
            .collect();
        let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_owned).collect()).collect();
        if rows.is_empty() {
            return Err(format!("{} has a header but no rows of figures", path.display()).into());
        }
        Ok(Table { path: path.to_path_buf(), header, rows })
    }

    fn column(&self, name: &str) -> Result<usize, Error> {
        self.header.iter().position(|h| h == name).ok_or_else(|| {
            format!(
                "{} has no column \"{name}\" (its columns: {}); is it a CSV of `cargo bench --features bench --bench render` or `--bench volume`?",
                self.path.display(),
                self.header.join(", ")
            )
            .into()
        })
    }

    /// The number in `row` (0: the first after the header) and `column`: finite
    /// and at most [`LARGEST_VALUE`] in magnitude, else an error naming both.
    fn number(&self, row: usize, column: usize) -> Result<f64, Error> {
        let name = &self.header[column];
        let at = || format!("line {}, column \"{name}\"", row + 2);
        let cell = self.rows[row].get(column).map(|c| c.trim()).unwrap_or_default();
        let value: f64 = cell.parse().map_err(|_| format!("{}: \"{cell}\" is not a number", at()))?;
        if !value.is_finite() || value.abs() > LARGEST_VALUE {
            return Err(format!(
                "{}: {cell} is not a plottable figure (finite, at most {LARGEST_VALUE:e} in magnitude)",
                at()
            )
            .into());
        }
        Ok(value)
    }
}

/// The chart of a panel: its caption and axes from 0 to `max_x` and `max_y`.
fn axes<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    caption: &str,
    max_x: f64,
    max_y: f64,
) -> Result<ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>, Error> {
    Ok(ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..max_x.max(1e-9), 0.0..max_y.max(1e-9))?)
}

fn line_chart(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    caption: &str,
    x_desc: &str,
    y_desc: &str,
    lines: &Lines,
    palette: &[String],
) -> Result<(), Error> {
    let all = lines.values().flatten();
    let max_x = all.clone().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    let max_y = all.map(|p| p.1).filter(|v| v.is_finite()).fold(0.0, f64::max) * 1.1;
    let mut chart = axes(area, caption, max_x, max_y)?;
    chart.configure_mesh().x_labels(6).x_label_formatter(&|x| short(*x)).x_desc(x_desc).y_desc(y_desc).draw()?;
    for (name, points) in lines {
        // The same name gets the same color in every panel.
        let color = Palette99::pick(palette.iter().position(|p| p == name).unwrap_or(0)).to_rgba();
        let points: Vec<(f64, f64)> = points.iter().copied().filter(|p| p.1.is_finite()).collect();
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
        chart.draw_series(points.iter().map(|p| Circle::new(*p, 3, color.filled())))?;
    }
    if lines.len() > 1 {
        chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.8)).draw()?;
    }
    Ok(())
}

/// An axis label that stays short: 250k, 1.5M; small values with one decimal.
fn short(x: f64) -> String {
    match x.abs() {
        a if a >= 1e6 => format!("{:.1}M", x / 1e6),
        a if a >= 1e4 => format!("{:.0}k", x / 1e3),
        _ => format!("{x:.1}"),
    }
}

fn render_lines(t: &Table) -> Result<(Lines, Lines), Error> {
    let (w, h, d) = (t.column("width")?, t.column("height")?, t.column("distance_m")?);
    let (seg, total) = (t.column("segments")?, t.column("total_ms")?);
    let ssaa = t.column("ssaa").ok();
    let (mut ms, mut segments) = (Lines::new(), Lines::new());
    let mut first_key = None;
    for r in 0..t.rows.len() {
        let supersampled = match ssaa {
            Some(i) => t.number(r, i)? > 0.0,
            None => false,
        };
        let key =
            format!("{}×{}{}", t.number(r, w)? as u32, t.number(r, h)? as u32, if supersampled { " SSAA" } else { "" });
        // One resolution's segment counts stand for all (LOD depends on distance only).
        if *first_key.get_or_insert_with(|| key.clone()) == key {
            segments.entry("segments".into()).or_default().push((t.number(r, d)?, t.number(r, seg)?));
        }
        ms.entry(key).or_default().push((t.number(r, d)?, t.number(r, total)?));
    }
    Ok((ms, segments))
}

fn volume_lines(t: &Table) -> Result<(Lines, Lines), Error> {
    let (grid, config) = (t.column("grid")?, t.column("config")?);
    let (ms, iterations) = (t.column("ms_per_step")?, t.column("pcg_iterations")?);
    let (mut time, mut solves) = (Lines::new(), Lines::new());
    for r in 0..t.rows.len() {
        let n = t.number(r, grid)?;
        if n <= 0.0 {
            continue; // the baseline row without a grid
        }
        let name = t.rows[r].get(config).cloned().unwrap_or_default();
        time.entry(name.clone()).or_default().push((n, t.number(r, ms)?));
        if !name.contains("friction") {
            solves.entry(name).or_default().push((n, t.number(r, iterations)?));
        }
    }
    if time.is_empty() {
        return Err(format!("{}: no row with a grid to plot", t.path.display()).into());
    }
    Ok((time, solves))
}

/// Charts the benchmark CSV `csv` into the PNG `out`.
pub fn plot_file(csv: &Path, out: &Path) -> Result<(), Error> {
    let table = Table::read(csv)?;
    let font = std::fs::read(FONT).map_err(|e| format!("{FONT}: {e} (install fonts-dejavu-core)"))?;
    plotters::style::register_font("sans-serif", FontStyle::Normal, Box::leak(font.into_boxed_slice()))
        .map_err(|_| "the DejaVu font could not be loaded")?;
    let size = if table.column("axis").is_ok() { SCALING_SIZE } else { SIZE };
    // Drawn in memory and written whole: a failed plot leaves no file.
    let mut rgb = vec![0u8; (size.0 * size.1 * 3) as usize];
    draw(&table, &mut rgb, size).map_err(|e| format!("cannot plot {}: {e}", csv.display()))?;
    let rgba: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    write_png(out, size.0, size.1, &rgba).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    say!("wrote {}", out.display());
    Ok(())
}

/// One panel per scaling axis: GPU and CPU-reference ms against the work.
fn scaling_panels(table: &Table, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), Error> {
    let (axis, unit, work) = (table.column("axis")?, table.column("unit")?, table.column("work")?);
    let (gpu, cpu) = (table.column("gpu_ms")?, table.column("cpu_ms")?);
    let mut axes: Vec<(String, String, Lines)> = Vec::new();
    for r in 0..table.rows.len() {
        let name = table.rows[r].get(axis).cloned().unwrap_or_default();
        if axes.last().is_none_or(|a| a.0 != name) {
            axes.push((name.clone(), table.rows[r].get(unit).cloned().unwrap_or_default(), Lines::new()));
        }
        let lines = &mut axes.last_mut().ok_or("no axis")?.2;
        let w = table.number(r, work)?;
        lines.entry("GPU".into()).or_default().push((w, table.number(r, gpu)?));
        // The render has no CPU reference: its cells are NaN.
        if let Ok(c) = table.number(r, cpu) {
            lines.entry("CPU reference".into()).or_default().push((w, c));
        }
    }
    let palette = vec!["GPU".to_owned(), "CPU reference".to_owned()];
    // Two panels a row, as many rows as the axes need.
    let panels = root.split_evenly((axes.len().div_ceil(2).max(1), 2));
    for ((name, unit, lines), area) in axes.iter().zip(panels.iter()) {
        line_chart(area, name, unit, "ms", lines, &palette)?;
    }
    Ok(())
}

/// Points with a label each, per series.
type Labelled = BTreeMap<String, Vec<(f64, f64, String)>>;

/// Each transparency mode's GPU ms and memory against its error (rows whose
/// error is not a number, a frame without hair, are left out and said).
fn mode_panels(table: &Table, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), Error> {
    let (scene, mode) = (table.column("scene")?, table.column("mode")?);
    let (ms, mib, error) = (table.column("gpu_ms")?, table.column("memory_mib")?, table.column("error_srgb_steps")?);
    let (mut time, mut memory) = (Labelled::new(), Labelled::new());
    let mut left_out = Vec::new();
    for r in 0..table.rows.len() {
        let name = table.rows[r].get(scene).cloned().unwrap_or_default();
        let label = table.rows[r].get(mode).cloned().unwrap_or_default();
        let Ok(e) = table.number(r, error) else {
            if left_out.len() < NAMED_ROWS {
                say!("{name}, {label}: no error figure (line {}), left out of the chart", r + 2);
            }
            left_out.push(r);
            continue;
        };
        time.entry(name.clone()).or_default().push((e, table.number(r, ms)?, label.clone()));
        memory.entry(name).or_default().push((e, table.number(r, mib)?, label));
    }
    if left_out.len() > NAMED_ROWS {
        say!("… and {} more rows without an error figure, left out of the chart", left_out.len() - NAMED_ROWS);
    }
    if time.is_empty() {
        return Err(format!("{}: no row has an error figure to plot", table.path.display()).into());
    }
    let palette: Vec<String> = time.keys().cloned().collect();
    let (left, right) = root.split_horizontally(SIZE.0 / 2);
    let x = "error against the exact reference (8-bit sRGB steps)";
    let caption = "GPU ms per frame (Kn: exact, n sorted; *: default)";
    scatter_chart(&left, caption, x, "GPU ms per frame", &time, &palette)?;
    scatter_chart(&right, "transparency memory", x, "MiB", &memory, &palette)?;
    Ok(())
}

/// A scatter chart of labelled points, one colour per series.
fn scatter_chart(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    caption: &str,
    x_desc: &str,
    y_desc: &str,
    series: &Labelled,
    palette: &[String],
) -> Result<(), Error> {
    let all = series.values().flatten();
    let max_x = all.clone().map(|p| p.0).fold(0.0, f64::max) * 1.25;
    let max_y = all.map(|p| p.1).fold(0.0, f64::max) * 1.15;
    let mut chart = axes(area, caption, max_x, max_y)?;
    chart.configure_mesh().x_labels(6).x_desc(x_desc).y_desc(y_desc).draw()?;
    for (name, points) in series {
        let color = Palette99::pick(palette.iter().position(|p| p == name).unwrap_or(0)).to_rgba();
        chart
            .draw_series(points.iter().map(|p| Circle::new((p.0, p.1), 4, color.filled())))?
            .label(name.clone())
            .legend(move |(x, y)| Circle::new((x + 9, y), 4, color.filled()));
        let font = ("sans-serif", 13).into_font().color(&color);
        // Labels staggered in three rows so that close points stay readable.
        chart.draw_series(points.iter().enumerate().map(|(i, p)| {
            EmptyElement::at((p.0, p.1)) + Text::new(short_mode(&p.2), (6, -16 + 12 * (i % 3) as i32), font.clone())
        }))?;
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.8)).draw()?;
    Ok(())
}

/// A mode's chart label: "exact K = 8 (default)" → "K8*", others as they are.
fn short_mode(mode: &str) -> String {
    match mode.strip_prefix("exact K = ") {
        Some(rest) => {
            let default = rest.contains("default");
            format!("K{}{}", rest.split_whitespace().next().unwrap_or(rest), if default { "*" } else { "" })
        }
        None => mode.to_owned(),
    }
}

/// Chart size of the scaling curves (four panels), pixels.
const SCALING_SIZE: (u32, u32) = (1100, 900);

/// Draws the chart's panels into an RGB buffer of `size`.
fn draw(table: &Table, rgb: &mut [u8], size: (u32, u32)) -> Result<(), Error> {
    let root = BitMapBackend::with_buffer(rgb, size).into_drawing_area();
    root.fill(&WHITE)?;
    if table.column("axis").is_ok() {
        scaling_panels(table, &root)?;
        root.present()?;
        return Ok(());
    }
    if table.column("mode").is_ok() {
        mode_panels(table, &root)?;
        root.present()?;
        return Ok(());
    }
    let (left, right) = root.split_horizontally(600);
    if table.column("pcg_iterations").is_ok() {
        let (time, solves) = volume_lines(table)?;
        let palette: Vec<String> = time.keys().cloned().collect();
        let caption = "vkhair volume: ms per step (thesis)";
        line_chart(&left, caption, "grid cells per axis", "ms per step", &time, &palette)?;
        line_chart(&right, "PCG iterations per step", "grid cells per axis", "iterations", &solves, &palette)?;
    } else {
        let (ms, segments) = render_lines(table)?;
        let palette: Vec<String> = ms.keys().chain(segments.keys()).cloned().collect();
        let caption = "vkhair render: GPU ms per frame (thesis scene)";
        line_chart(&left, caption, "camera distance (m)", "GPU ms (all hair passes)", &ms, &palette)?;
        let caption = "segments drawn (level of detail)";
        line_chart(&right, caption, "camera distance (m)", "segments", &segments, &palette)?;
    }
    root.present()?;
    Ok(())
}
