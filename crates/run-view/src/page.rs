//! The page: scenes as HTML with their data, the viewer's script and style sheet inline, so
//! that a page opens from `file://` with no network (no CDN, no fonts from elsewhere).

use crate::error::ViewError;
use crate::view::Scene;

/// The viewer's script (`assets/viewer.js`, one readable file with its own tests).
pub const SCRIPT: &str = include_str!("../assets/viewer.js");
/// The viewer's style sheet.
pub const STYLE: &str = include_str!("../assets/viewer.css");
/// Samples a run keeps in a page of one run ([`RunView::decimated`](crate::RunView::decimated)):
/// about 55 a second of a 5.5 s run, smooth to play and light to embed.
pub const PAGE_SAMPLES: usize = 300;
/// Samples a run keeps in a page of many runs (the main job's report, 43 runs): about 36 a
/// second of a 5.5 s run; the viewer interpolates between them.
pub const REPORT_SAMPLES: usize = 200;

/// `text` with the characters that mean something in HTML (`& < > " '`) replaced by entities,
/// safe inside elements and quoted attributes.
///
/// ```
/// assert_eq!(run_view::escape("<a href='x'>&</a>"), "&lt;a href=&#39;x&#39;&gt;&amp;&lt;/a&gt;");
/// ```
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

/// One scene as an HTML block: its heading, caption and an element the script turns into the
/// viewer, holding the scene's runs decimated to `samples` samples as JSON. The scene is
/// checked first ([`Scene::check`]).
pub fn scene_html(scene: &Scene, samples: usize) -> Result<String, ViewError> {
    scene.check()?;
    let decimated = Scene {
        runs: scene.runs.iter().map(|r| r.decimated(samples)).collect(),
        ..scene.clone()
    };
    let json = serde_json::to_string(&decimated)?;
    // `<` only occurs inside JSON strings, where `\u003c` means the same: no `</script>` or
    // `<!--` can end the data block early.
    let json = json.replace('<', "\\u003c");
    Ok(format!(
        "<section class=\"hrm-scene\">\n<h3>{}</h3>\n<p class=\"hrm-caption\">{}</p>\n<div class=\"hrm-view\"><script type=\"application/json\">{json}</script></div>\n</section>\n",
        escape(&scene.title),
        escape(&scene.caption)
    ))
}

/// What every page and GIF hrm writes carries (a `generator` meta element, a GIF comment), so
/// that hrm replaces only files it wrote ([`written_by_hrm`]).
pub const SIGNATURE: &str = "written by hrm";

/// Whether a file beginning with `start` (its first [`SIGNATURE_WITHIN`] bytes or fewer) is a
/// page or GIF hrm wrote: a GIF carrying the [`SIGNATURE`] as a comment extension, or an HTML
/// document carrying it as the `generator` meta element of [`head`]. A text that merely
/// mentions the signature (a user's notes) is not one.
pub fn written_by_hrm(start: &[u8]) -> bool {
    let contains = |needle: &[u8]| start.windows(needle.len()).any(|w| w == needle);
    if start.starts_with(b"GIF8") {
        // The comment: its introducer and label, the length of its one block, the text.
        let mut comment = vec![0x21, 0xFE, SIGNATURE.len() as u8];
        comment.extend_from_slice(SIGNATURE.as_bytes());
        contains(&comment)
    } else {
        start.starts_with(b"<!DOCTYPE html>") && contains(generator().as_bytes())
    }
}

/// The `generator` meta element that carries the [`SIGNATURE`] in a page's head.
fn generator() -> String {
    format!("<meta name=\"generator\" content=\"{SIGNATURE}\">")
}

/// How far into a page or GIF its [`SIGNATURE`] is: within the first 2 KiB.
pub const SIGNATURE_WITHIN: usize = 2048;

/// The signature, the viewport (so that a phone lays the page out at its own width), style
/// sheet and script every page with scenes carries once: put [`head`] in the `<head>` (it opens
/// it, right after the charset) and [`tail`] at the end of the `<body>`.
pub fn head() -> String {
    format!(
        "{}\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<style>{STYLE}</style>\n",
        generator()
    )
}

/// The viewer's script, to close the `<body>` of a page with scenes.
pub fn tail() -> String {
    // The script never holds `</script`; a test checks it.
    format!("<script>\n{SCRIPT}</script>\n")
}

/// A whole page: `title`, an `intro` paragraph, and every scene with its viewer.
pub fn page(
    title: &str,
    intro: &str,
    scenes: &[Scene],
    samples: usize,
) -> Result<String, ViewError> {
    let mut body = String::new();
    for scene in scenes {
        let html = scene_html(scene, samples)?;
        // A page of one scene under the scene's own title does not repeat it.
        let repeated = format!("<h3>{}</h3>\n", escape(&scene.title));
        if scenes.len() == 1 && scene.title == title {
            body.push_str(&html.replacen(&repeated, "", 1));
        } else {
            body.push_str(&html);
        }
    }
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n{1}<title>{0}</title>\n<style>body{{font-family:sans-serif;margin:1.5em;max-width:1500px;color:#222}}</style>\n</head>\n<body>\n<h1>{0}</h1>\n<p>{2}</p>\n{body}{3}</body>\n</html>\n",
        escape(title),
        head(),
        escape(intro),
        tail()
    ))
}

/// `page` inside an `<iframe srcdoc>` of `height` pixels: what a Jupyter cell shows, its
/// script and styles kept apart from the notebook's.
pub fn iframe(page: &str, height: u32) -> String {
    format!(
        "<iframe srcdoc=\"{}\" style=\"width:100%;height:{height}px;border:0\" sandbox=\"allow-scripts\"></iframe>",
        escape(page)
    )
}
