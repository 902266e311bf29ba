//! `polydem plot`: the time series a user looks at first, as PNG plots with labelled axes and
//! units: the energy terms and the ledger's closure (`energy.csv`), the contact and body counts
//! and the packing fraction (also `energy.csv`), mass flow (`flow.csv`) and the forces and
//! torques on the walls (`wall_forces.csv`), each only when the run wrote it.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::{register, FAMILY};
use super::overlay::format_value;
use super::text::TextBackend;
use super::{png, PictureError};
use crate::io::csv_read::{read_table, Table};

/// Line colours (matplotlib's tab10): distinct on white, none too pale.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// One line of a chart: its legend and its (time, value) points.
struct Line {
    label: String,
    points: Vec<(f64, f64)>,
}

/// One chart: a title, the y axis' label with unit, its lines.
struct Panel {
    title: String,
    y_label: String,
    lines: Vec<Line>,
}

type Area<'a> = DrawingArea<TextBackend<BitMapBackend<'a>>, Shift>;

fn draw_error(e: impl std::fmt::Display) -> PictureError {
    PictureError::Draw(e.to_string())
}

/// The finite range of the lines' x and y values, widened where it is empty so that plotters
/// gets a proper range.
fn ranges(lines: &[Line]) -> ((f64, f64), (f64, f64)) {
    let pad = |(low, high): (f64, f64), margin: f64| {
        if low > high {
            (0.0, 1.0)
        } else if high - low <= 1e-12 * high.abs().max(low.abs()) || high == low {
            let d = if low == 0.0 { 1.0 } else { 0.1 * low.abs() };
            (low - d, high + d)
        } else {
            let d = margin * (high - low);
            (low - d, high + d)
        }
    };
    let fold = |f: fn(&(f64, f64)) -> f64| {
        lines
            .iter()
            .flat_map(|l| l.points.iter().map(f))
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    (pad(fold(|p| p.0), 0.0), pad(fold(|p| p.1), 0.05))
}

fn draw_panel(area: &Area, panel: &Panel) -> Result<(), PictureError> {
    let (x_range, y_range) = ranges(&panel.lines);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FAMILY, 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(85)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .y_desc(&panel.y_label)
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 15))
        .x_label_formatter(&|v| format_value(*v))
        .y_label_formatter(&|v| format_value(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(draw_error)?;
    for (k, line) in panel.lines.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let points = line.points.iter().copied().filter(|p| p.1.is_finite());
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2)))
            .map_err(draw_error)?
            .label(&line.label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FAMILY, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(draw_error)?;
    Ok(())
}

/// Draws `panels` one under the other (or in a grid of `columns`) into a PNG file.
fn write_panels(path: &Path, panels: &[Panel], columns: usize) -> Result<(), PictureError> {
    register();
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns);
    let width = if columns == 1 { 1000 } else { 640 * columns };
    let height = 380 * rows;
    let mut rgb = vec![255u8; 3 * width * height];
    {
        let bitmap = BitMapBackend::with_buffer(&mut rgb, (width as u32, height as u32));
        let root = TextBackend::new(bitmap).into_drawing_area();
        root.fill(&WHITE).map_err(draw_error)?;
        for (area, panel) in root.split_evenly((rows, columns)).iter().zip(panels) {
            draw_panel(area, panel)?;
        }
        root.present().map_err(draw_error)?;
    }
    png::write_rgb(path, width, height, &rgb)
}

fn series(table: &Table, time: &[f64], column: &str, label: &str) -> Option<Line> {
    let values = table.column(column)?;
    Some(Line {
        label: label.to_string(),
        points: time.iter().copied().zip(values).collect(),
    })
}

/// The energy terms and the ledger closure; the counts; the packing fraction.
fn energy_plots(table: &Table, out: &Path) -> Result<Vec<PathBuf>, PictureError> {
    let time = table.column("time").ok_or_else(|| {
        PictureError::file(
            &table.path,
            "has no 'time' column: not an energy.csv of polydem",
        )
    })?;
    let mut terms = Vec::new();
    // The ledger's terms: every energy column but the time, the total and the counts.
    let not_terms = ["time", "total", "contacts", "bodies"];
    for column in crate::io::output::ENERGY_COLUMNS
        .into_iter()
        .filter(|c| !not_terms.contains(c))
    {
        let Some(mut line) = series(table, &time, column, column) else {
            continue;
        };
        // Terms that stay zero (no insertion, no moving wall) only crowd the legend.
        if line.points.iter().all(|p| p.1 == 0.0) {
            continue;
        }
        // The potential energy's zero is arbitrary (the height of the origin): its change is
        // what compares with the other terms.
        if column == "potential_gravity" {
            let start = line.points[0].1;
            line.points.iter_mut().for_each(|p| p.1 -= start);
            line.label = "potential_gravity − start".into();
        }
        terms.push(line);
    }
    let mut written = Vec::new();
    let mut panels = vec![Panel {
        title: "Energy terms".into(),
        y_label: "energy [J]".into(),
        lines: terms,
    }];
    if let Some(mut closure) = series(table, &time, "total", "total − total at start") {
        let start = closure.points[0].1;
        closure.points.iter_mut().for_each(|p| p.1 -= start);
        panels.push(Panel {
            title: "Energy ledger closure (0 when every joule is accounted for)".into(),
            y_label: "energy [J]".into(),
            lines: vec![closure],
        });
    }
    let path = out.join("energy.png");
    write_panels(&path, &panels, 1)?;
    written.push(path);

    let counts: Vec<Line> = ["contacts", "bodies"]
        .iter()
        .filter_map(|c| series(table, &time, c, c))
        .collect();
    if !counts.is_empty() {
        let path = out.join("contacts.png");
        let panel = Panel {
            title: "Contacts and bodies".into(),
            y_label: "count".into(),
            lines: counts,
        };
        write_panels(&path, &[panel], 1)?;
        written.push(path);
    }
    if let Some(packing) = series(table, &time, "packing_fraction", "packing fraction") {
        let path = out.join("packing.png");
        let panel = Panel {
            title: "Packing fraction of the packing region".into(),
            y_label: "solid fraction [-]".into(),
            lines: vec![packing],
        };
        write_panels(&path, &[panel], 1)?;
        written.push(path);
    }
    Ok(written)
}

/// Mass passed and mass flow rate, one line per meter (`<meter>_mass`, `<meter>_rate`).
fn flow_plot(table: &Table, out: &Path) -> Result<Option<PathBuf>, PictureError> {
    let Some(time) = table.column("time") else {
        return Err(PictureError::file(&table.path, "has no 'time' column"));
    };
    let meters: Vec<&str> = table
        .columns
        .iter()
        .filter_map(|c| c.strip_suffix("_mass"))
        .collect();
    let lines = |suffix: &str| -> Vec<Line> {
        meters
            .iter()
            .filter_map(|m| series(table, &time, &format!("{m}_{suffix}"), m))
            .collect()
    };
    let panels = [
        Panel {
            title: "Mass passed through each meter since the start".into(),
            y_label: "mass [kg]".into(),
            lines: lines("mass"),
        },
        Panel {
            title: "Mass flow rate (mean over each output interval)".into(),
            y_label: "mass flow rate [kg/s]".into(),
            lines: lines("rate"),
        },
    ];
    let path = out.join("flow.png");
    write_panels(&path, &panels, 1)?;
    Ok(Some(path))
}

/// Force and torque components per wall (`wall<k>_fx` … `wall<k>_tz`), a row of two charts
/// per wall.
fn wall_plot(table: &Table, out: &Path) -> Result<Option<PathBuf>, PictureError> {
    let Some(time) = table.column("time") else {
        return Err(PictureError::file(&table.path, "has no 'time' column"));
    };
    let walls: Vec<&str> = table
        .columns
        .iter()
        .filter_map(|c| c.strip_suffix("_fx"))
        .collect();
    let mut panels = Vec::new();
    for wall in walls {
        let lines = |parts: [&str; 3]| -> Vec<Line> {
            parts
                .iter()
                .filter_map(|c| series(table, &time, &format!("{wall}_{c}"), c))
                .collect()
        };
        panels.push(Panel {
            title: format!("{wall}: mean force on it"),
            y_label: "force [N]".into(),
            lines: lines(["fx", "fy", "fz"]),
        });
        panels.push(Panel {
            title: format!("{wall}: mean torque about its reference point"),
            y_label: "torque [N m]".into(),
            lines: lines(["tx", "ty", "tz"]),
        });
    }
    if panels.is_empty() {
        return Ok(None);
    }
    let path = out.join("wall_forces.png");
    write_panels(&path, &panels, 2)?;
    Ok(Some(path))
}

/// Plots the CSV series of the run in `dir` into `out`; returns the files written.
pub fn plot_run(dir: &Path, out: &Path) -> Result<Vec<PathBuf>, PictureError> {
    let energy = dir.join("energy.csv");
    if !energy.is_file() {
        return Err(PictureError::file(
            dir,
            "has no energy.csv: give the output folder of `polydem run`",
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| PictureError::file(out, e.to_string()))?;
    let read = |path: &Path| read_table(path).map_err(PictureError::Table);
    let table = read(&energy)?;
    if table.rows.is_empty() {
        return Err(PictureError::file(&energy, "has no rows yet"));
    }
    let mut written = energy_plots(&table, out)?;
    // These two get their first row at the second output time: a run of one frame has none.
    for (name, plot) in [
        ("flow.csv", flow_plot as fn(&Table, &Path) -> _),
        ("wall_forces.csv", wall_plot),
    ] {
        let path = dir.join(name);
        if !path.is_file() {
            continue;
        }
        let table = read(&path)?;
        if table.rows.is_empty() {
            continue;
        }
        written.extend(plot(&table, out)?);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::output::ENERGY_COLUMNS;
    use crate::io::CsvSeries;

    /// A run folder with every CSV series a run can write, ten rows each.
    fn write_series(dir: &Path) {
        let mut energy_columns = ENERGY_COLUMNS.to_vec();
        energy_columns.push("packing_fraction");
        let mut energy = CsvSeries::new(dir.join("energy.csv"), &energy_columns);
        let mut flow = CsvSeries::new(
            dir.join("flow.csv"),
            &["time", "outlet_mass", "outlet_bodies", "outlet_rate"],
        );
        let mut walls = CsvSeries::new(
            dir.join("wall_forces.csv"),
            &[
                "time", "wall0_fx", "wall0_fy", "wall0_fz", "wall0_tx", "wall0_ty", "wall0_tz",
            ],
        );
        for k in 0..10 {
            let t = 0.1 * k as f64;
            let row: Vec<f64> = energy_columns
                .iter()
                .map(|&c| match c {
                    "time" => t,
                    "kinetic_translational" => 1.0 / (1.0 + t),
                    "kinetic_rotational" => 0.1,
                    "potential_gravity" => -t,
                    "dissipated" => t,
                    "total" => 1.0,
                    "contacts" => (100 * k) as f64,
                    "bodies" => 50.0,
                    "packing_fraction" => 0.5 + 0.01 * t,
                    _ => 0.0,
                })
                .collect();
            energy.push(&row).unwrap();
            if k > 0 {
                flow.push(&[t, 0.2 * t, (3 * k) as f64, 0.2]).unwrap();
                walls
                    .push(&[t, 0.0, 1.0, -9.81 * t, 0.0, 0.0, 0.5])
                    .unwrap();
            }
        }
    }

    /// How many pixels of a PNG are not white: a plot with axes, labels and lines has many.
    fn ink(path: &Path) -> (u32, u32, usize) {
        let image = image::open(path).unwrap().to_rgb8();
        let ink = image.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        (image.width(), image.height(), ink)
    }

    #[test]
    fn every_series_is_plotted() {
        let dir = tempfile::tempdir().unwrap();
        write_series(dir.path());
        let out = dir.path().join("plots");
        let written = plot_run(dir.path(), &out).unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "energy.png",
                "contacts.png",
                "packing.png",
                "flow.png",
                "wall_forces.png"
            ]
        );
        for path in &written {
            let (w, h, ink) = ink(path);
            assert!(w >= 1000 && h >= 380, "{}: {w}x{h}", path.display());
            assert!(ink > 5000, "{}: {ink} pixels of ink", path.display());
        }
        // Two panels under each other; one wall gives a row of two.
        assert_eq!(ink(&out.join("energy.png")).1, 760);
        assert_eq!(ink(&out.join("wall_forces.png")).0, 1280);
    }

    #[test]
    fn missing_and_broken_series_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let err = plot_run(dir.path(), dir.path()).unwrap_err().to_string();
        assert!(err.contains("energy.csv"), "{err}");
        write_series(dir.path());
        std::fs::write(dir.path().join("flow.csv"), "time,outlet_mass\n0.1,oops\n").unwrap();
        let err = plot_run(dir.path(), dir.path()).unwrap_err().to_string();
        assert!(err.contains("flow.csv") && err.contains("line 2"), "{err}");
    }

    #[test]
    fn a_constant_or_empty_series_still_gets_a_range() {
        let flat = Line {
            label: "flat".into(),
            points: vec![(0.0, 2.0), (1.0, 2.0)],
        };
        let ((x0, x1), (y0, y1)) = ranges(&[flat]);
        assert!(x0 < x1 && y0 < 2.0 && y1 > 2.0);
        let ((x0, x1), (y0, y1)) = ranges(&[]);
        assert!(x0 < x1 && y0 < y1);
    }
}
