//! `report.html`: one self-contained page (no scripts, no style sheets or fonts from elsewhere)
//! with the main job's comparison table and every figure, each with a caption.

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
const STYLE: &str = "body{font-family:sans-serif;margin:2em;max-width:1700px;color:#222}\
table{border-collapse:collapse;font-size:0.9em}th,td{border:1px solid #bbb;padding:0.25em 0.6em}\
td.num{text-align:right;font-variant-numeric:tabular-nums}td.error{color:#a00}\
th{background:#eee}figure{display:inline-block;vertical-align:top;margin:0.5em;width:620px}\
figure img{width:100%;border:1px solid #ddd}figcaption{font-size:0.9em}";

/// Writes the report with `title`, an `intro` paragraph, `table` and `sections` to `path`.
pub fn write(
    path: &Path,
    title: &str,
    intro: &str,
    table: &Table,
    sections: &[Section],
) -> Result<(), String> {
    std::fs::write(path, html(title, intro, table, sections))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The page's HTML.
fn html(title: &str, intro: &str, table: &Table, sections: &[Section]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n<p>{}</p>\n",
        escape(title),
        escape(title),
        escape(intro)
    );
    s.push_str("<h2>Comparison</h2>\n<table>\n<tr>");
    for header in &table.headers {
        let _ = write!(s, "<th>{}</th>", escape(header));
    }
    s.push_str("</tr>\n");
    for row in &table.rows {
        s.push_str("<tr>");
        for (k, cell) in row.cells.iter().enumerate() {
            let class = if k < 2 { "" } else { " class=\"num\"" };
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
    s.push_str("</body>\n</html>\n");
    s
}

/// `text` with the characters that mean something in HTML (`& < > " '`) replaced by entities,
/// safe inside elements and quoted attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_replaces_every_markup_character_and_keeps_the_rest() {
        assert_eq!(
            escape(r#"<a href="x">Tom & 'Jerry'</a> é"#),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt; é"
        );
        assert_eq!(escape("&amp;"), "&amp;amp;");
        assert_eq!(escape(""), "");
    }

    #[test]
    fn the_page_has_one_row_per_run_escaped_errors_and_every_figure() {
        let table = Table {
            headers: ["scenario", "controller", "tip rms mm", "effort"]
                .map(String::from)
                .to_vec(),
            rows: vec![
                Row {
                    cells: ["s", "pd", "1.5", "2e3"].map(String::from).to_vec(),
                    error: None,
                },
                Row {
                    cells: ["s", "fuzzy"].map(String::from).to_vec(),
                    error: Some("|a| > 10 <rad>".into()),
                },
            ],
        };
        let sections = [Section {
            title: "Figures & more".into(),
            text: "x < y".into(),
            figures: vec![Figure {
                file: "figures/a b.svg".into(),
                caption: "a \"quoted\" caption".into(),
            }],
        }];
        let page = html("T", "intro", &table, &sections);
        assert_eq!(page.matches("<tr>").count(), 1 + 2);
        assert!(
            page.contains(
                "<td class=\"error\" colspan=\"2\">stopped: |a| &gt; 10 &lt;rad&gt;</td>"
            )
        );
        assert!(
            page.contains("<img src=\"figures/a b.svg\" alt=\"a &quot;quoted&quot; caption\">")
        );
        assert!(page.contains("<h2>Figures &amp; more</h2>\n<p>x &lt; y</p>"));
        assert!(!page.contains("<script") && !page.contains("http"));
        let bad = Path::new("/nonexistent-hrm-dir/report.html");
        let err = write(bad, "T", "", &table, &sections).unwrap_err();
        assert!(err.contains("/nonexistent-hrm-dir/report.html"), "{err}");
    }
}
