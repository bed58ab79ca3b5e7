//! `vkhair plot`: the render benchmark's CSV (benches/render.rs) as a PNG chart —
//! GPU ms per frame against camera distance, one line per resolution, with the
//! drawn segment count on a second panel.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

/// Where Debian's fonts-dejavu-core puts the font the chart is labelled with.
const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

#[derive(clap::Args)]
pub struct PlotArgs {
    /// CSV written by `cargo bench --bench render`.
    #[arg(default_value = "target/vkhair-bench/render.csv")]
    csv: PathBuf,
    /// Output PNG.
    #[arg(long, default_value = "target/vkhair-bench/render.png")]
    out: PathBuf,
}

type Series = BTreeMap<String, Vec<(f64, f64, f64)>>;

fn read(path: &Path) -> Result<Series, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty CSV")?.split(',').collect();
    let column =
        |name: &str| header.iter().position(|h| *h == name).ok_or_else(|| format!("CSV has no column {name:?}"));
    let (w, h, d, seg, total) =
        (column("width")?, column("height")?, column("distance_m")?, column("segments")?, column("total_ms")?);
    let ssaa = column("ssaa").ok();
    let mut series = Series::new();
    for (n, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let cell = |i: usize| -> Result<f64, String> {
            cells
                .get(i)
                .and_then(|c| c.trim().parse::<f64>().ok())
                .ok_or_else(|| format!("line {}: bad value in column {i}", n + 2))
        };
        let supersampled = match ssaa {
            Some(i) => cell(i)? > 0.0,
            None => false,
        };
        let key = format!("{}×{}{}", cell(w)? as u32, cell(h)? as u32, if supersampled { " SSAA" } else { "" });
        series.entry(key).or_default().push((cell(d)?, cell(total)?, cell(seg)?));
    }
    if series.is_empty() {
        return Err("the CSV has no rows".into());
    }
    Ok(series)
}

pub fn plot(a: &PlotArgs) -> Result<(), Box<dyn std::error::Error>> {
    let series = read(&a.csv)?;
    let font = std::fs::read(FONT).map_err(|e| format!("{FONT}: {e} (install fonts-dejavu-core)"))?;
    plotters::style::register_font("sans-serif", FontStyle::Normal, Box::leak(font.into_boxed_slice()))
        .map_err(|_| "the DejaVu font could not be loaded")?;
    let all = series.values().flatten();
    let max_d = all.clone().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    let max_ms = all.clone().map(|p| p.1).fold(0.0, f64::max) * 1.1;
    let max_seg = all.map(|p| p.2).fold(0.0, f64::max) * 1.1;
    let root = BitMapBackend::new(&a.out, (1100, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(600);
    let mut chart = ChartBuilder::on(&left)
        .caption("vkhair render: GPU ms per frame (thesis scene)", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..max_d, 0.0..max_ms)?;
    chart.configure_mesh().x_desc("camera distance (m)").y_desc("GPU ms (all hair passes)").draw()?;
    for (k, (name, points)) in series.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        chart
            .draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), color.stroke_width(2)))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
        chart.draw_series(points.iter().map(|p| Circle::new((p.0, p.1), 3, color.filled())))?;
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.8)).draw()?;
    let mut segments = ChartBuilder::on(&right)
        .caption("segments drawn (level of detail)", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..max_d, 0.0..max_seg)?;
    segments.configure_mesh().x_desc("camera distance (m)").y_desc("segments").draw()?;
    if let Some(points) = series.values().next() {
        segments.draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.2)), BLUE.stroke_width(2)))?;
        segments.draw_series(points.iter().map(|p| Circle::new((p.0, p.2), 3, BLUE.filled())))?;
    }
    root.present()?;
    println!("wrote {}", a.out.display());
    Ok(())
}
