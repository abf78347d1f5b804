//! `report.html`: one self-contained page (no style sheets, scripts or fonts from elsewhere)
//! with the main job's comparison, one table per scenario (the best value of each column
//! marked) with the animation of its runs (`run-view`), then every figure with a caption.

use run_view::Scene;
pub use run_view::escape;
use std::fmt::Write as _;
use std::path::Path;

/// A table: column headings and one row per run.
pub struct Table {
    /// Column headings.
    pub headers: Vec<String>,
    /// The rows.
    pub rows: Vec<Row>,
}

/// One row of a [`Table`]: the leading cells (e.g. scenario and controller), then either the
/// remaining cells or why there are none.
pub struct Row {
    /// The cells, left to right.
    pub cells: Vec<String>,
    /// Set when the run failed: shown across the columns the cells leave empty.
    pub error: Option<String>,
}

/// The runs of one scenario: a heading, a line about the scenario, its table (the first
/// `names` columns are names, the rest numbers, lower better) and the animation of its runs.
pub struct Group {
    /// The heading (the scenario's name).
    pub title: String,
    /// What the scenario is.
    pub text: String,
    /// Its runs.
    pub table: Table,
    /// How many leading columns hold names rather than numbers.
    pub names: usize,
    /// The animation of its runs, when any has data.
    pub scene: Option<Scene>,
}

/// A figure of the report: an image file (relative to the report, `/`-separated) and a caption.
pub struct Figure {
    /// The image's path relative to the report.
    pub file: String,
    /// What the figure shows.
    pub caption: String,
}

/// A titled group of figures, shown side by side where they fit.
pub struct Section {
    /// The heading.
    pub title: String,
    /// A paragraph under the heading.
    pub text: String,
    /// The figures.
    pub figures: Vec<Figure>,
}

/// Inline style sheet: the page carries its own.
const STYLE: &str = "body{font-family:sans-serif;margin:2em;max-width:1500px;color:#222}\
table{border-collapse:collapse;font-size:0.9em;margin:0.4em 0;display:block;overflow-x:auto;max-width:100%}th,td{border:1px solid #bbb;padding:0.25em 0.6em}\
td.num{text-align:right;font-variant-numeric:tabular-nums}td.best{font-weight:bold;background:#e8f4e8}\
td.error{color:#a00}th{background:#eee;font-weight:normal}\
figure{display:inline-block;vertical-align:top;margin:0.5em;width:620px;max-width:calc(100% - 1em)}\
figure img{width:100%;border:1px solid #ddd}figcaption{font-size:0.9em}";

/// Writes the report with `title`, an `intro` paragraph, a table and an animation per
/// scenario (`groups`, each run decimated to `samples` samples) and `sections` of figures to
/// `path`.
pub fn write(
    path: &Path,
    title: &str,
    intro: &str,
    groups: &[Group],
    sections: &[Section],
    samples: usize,
) -> Result<(), String> {
    let page = html(title, intro, groups, sections, samples)?;
    std::fs::write(path, page).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The page's HTML.
fn html(
    title: &str,
    intro: &str,
    groups: &[Group],
    sections: &[Section],
    samples: usize,
) -> Result<String, String> {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n{1}<title>{0}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{0}</h1>\n<p>{2}</p>\n",
        escape(title),
        run_view::head(),
        escape(intro)
    );
    if !groups.is_empty() {
        s.push_str("<h2>Comparison by scenario</h2>\n<p>Lower is better in every column; the best value of each column within a scenario is <b>bold</b>. Under each table, its runs play in sync with their time series: drag the slider, press space to play, compare two controllers side by side or overlaid.</p>\n");
    }
    for group in groups {
        let _ = writeln!(
            s,
            "<h3 id=\"{0}\">{0}</h3>\n<p>{1}</p>",
            escape(&group.title),
            escape(&group.text)
        );
        table_html(&mut s, &group.table, group.names);
        if let Some(scene) = &group.scene {
            s.push_str(&run_view::scene_html(scene, samples).map_err(|e| e.to_string())?);
        }
    }
    for section in sections {
        let _ = writeln!(
            s,
            "<h2>{}</h2>\n<p>{}</p>",
            escape(&section.title),
            escape(&section.text)
        );
        for figure in &section.figures {
            let _ = writeln!(
                s,
                "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{1}</figcaption></figure>",
                escape(&figure.file),
                escape(&figure.caption)
            );
        }
    }
    s.push_str(&run_view::tail());
    s.push_str("</body>\n</html>\n");
    Ok(s)
}

/// Appends `table` to `s`, the lowest number of each column (over two or more rows) marked.
fn table_html(s: &mut String, table: &Table, names: usize) {
    let best: Vec<Option<f64>> = (0..table.headers.len())
        .map(|k| {
            let values: Vec<f64> = table
                .rows
                .iter()
                .filter(|r| r.error.is_none())
                .filter_map(|r| r.cells.get(k)?.parse::<f64>().ok())
                .collect();
            (k >= names && values.len() >= 2)
                .then(|| values.into_iter().fold(f64::INFINITY, f64::min))
        })
        .collect();
    s.push_str("<table>\n<tr>");
    for header in &table.headers {
        // The unit on a line of its own: `tip error RMS` over `(mm)`.
        match header.strip_suffix(')').and_then(|h| h.rsplit_once(" (")) {
            Some((name, unit)) => {
                let _ = write!(s, "<th>{}<br>({})</th>", escape(name), escape(unit));
            }
            None => {
                let _ = write!(s, "<th>{}</th>", escape(header));
            }
        }
    }
    s.push_str("</tr>\n");
    for row in &table.rows {
        s.push_str("<tr>");
        for (k, cell) in row.cells.iter().enumerate() {
            let class = match best[k] {
                Some(b) if row.error.is_none() && cell.parse::<f64>() == Ok(b) => {
                    " class=\"num best\""
                }
                _ if k < names => "",
                _ => " class=\"num\"",
            };
            let _ = write!(s, "<td{class}>{}</td>", escape(cell));
        }
        if let Some(error) = &row.error {
            let span = table.headers.len().saturating_sub(row.cells.len()).max(1);
            let _ = write!(
                s,
                "<td class=\"error\" colspan=\"{span}\">stopped: {}</td>",
                escape(error)
            );
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
}

/// `v` in plain notation (never `3.2e1`) with `significant` digits, at most 6 decimals.
///
/// Numbers of a report are read, not parsed back: enough digits to compare controllers.
pub fn plain(v: f64, significant: i32) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (significant - 1 - magnitude).clamp(0, 6) as usize;
    let text = format!("{v:.decimals$}");
    if text
        .trim_start_matches('-')
        .trim_start_matches(['0', '.'])
        .is_empty()
    {
        "0".into()
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_plainly() {
        assert_eq!(plain(32.113, 4), "32.11");
        assert_eq!(plain(0.0048312, 3), "0.00483");
        assert_eq!(plain(123_456.7, 4), "123457");
        assert_eq!(plain(-1.0e-9, 3), "0");
        assert_eq!(plain(0.0, 3), "0");
        assert_eq!(plain(f64::NAN, 3), "NaN");
        for v in [3.2113e1, 1e-3, 2.5e7, 0.1 + 0.2] {
            assert!(!plain(v, 4).contains('e'), "{v}");
        }
    }

    #[test]
    fn each_scenario_has_its_table_with_the_best_values_marked() {
        let headers: Vec<String> = ["controller", "tip RMS (mm)", "effort (N\u{b2} m\u{b2} s)"]
            .map(String::from)
            .to_vec();
        let row = |cells: [&str; 3]| Row {
            cells: cells.map(String::from).to_vec(),
            error: None,
        };
        let groups = [
            Group {
                title: "s & t".into(),
                text: "x < y".into(),
                table: Table {
                    headers: headers.clone(),
                    rows: vec![
                        row(["pd", "1.5", "20"]),
                        row(["fuzzy", "0.9", "20"]),
                        Row {
                            cells: vec!["lqr".into()],
                            error: Some("|a| > 10 <rad>".into()),
                        },
                    ],
                },
                names: 1,
                scene: None,
            },
            Group {
                title: "alone".into(),
                text: String::new(),
                table: Table {
                    headers,
                    rows: vec![row(["pd", "1.5", "20"])],
                },
                names: 1,
                scene: None,
            },
        ];
        let sections = [Section {
            title: "Figures & more".into(),
            text: "x < y".into(),
            figures: vec![Figure {
                file: "figures/a b.svg".into(),
                caption: "a \"quoted\" caption".into(),
            }],
        }];
        let page = html("T", "intro", &groups, &sections, 100).unwrap();
        assert_eq!(page.matches("<table>").count(), 2);
        assert_eq!(page.matches("<tr>").count(), 2 + 3 + 1);
        assert!(page.contains("<h3 id=\"s &amp; t\">s &amp; t</h3>\n<p>x &lt; y</p>"));
        assert!(page.contains("<th>controller</th><th>tip RMS<br>(mm)</th>"));
        // The lowest tip error is marked, a tie marks both, a lone row marks nothing.
        assert!(page.contains(
            "<td>fuzzy</td><td class=\"num best\">0.9</td><td class=\"num best\">20</td>"
        ));
        assert!(
            page.contains("<td>pd</td><td class=\"num\">1.5</td><td class=\"num best\">20</td>")
        );
        assert_eq!(page.matches("num best").count(), 3);
        assert!(
            page.contains(
                "<td class=\"error\" colspan=\"2\">stopped: |a| &gt; 10 &lt;rad&gt;</td>"
            )
        );
        assert!(
            page.contains("<img src=\"figures/a b.svg\" alt=\"a &quot;quoted&quot; caption\">")
        );
        assert!(!page.contains("http://") && !page.contains("https://"));
        let bad = Path::new("/nonexistent-hrm-dir/report.html");
        let err = write(bad, "T", "", &groups, &sections, 100).unwrap_err();
        assert!(err.contains("/nonexistent-hrm-dir/report.html"), "{err}");
    }
}
