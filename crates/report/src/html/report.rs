//! The single-file HTML report ([`Report`]).
//!
//! A report is a title and a list of blocks: section headings, paragraphs,
//! tables, key–value lists and figures. [`Report::to_html`] renders one
//! self-contained HTML5 document: inline CSS, figures as inline SVG, no
//! scripts, fonts, images or links to anything outside the file, so it can
//! be mailed or archived as is. A table of contents is generated from the
//! sections; sections, figures and tables are numbered in order.
//!
//! All user text (title, headings, paragraphs, table cells, captions, keys,
//! values) is HTML-escaped. Figure SVG is inserted verbatim: it must be
//! trusted markup such as the output of [`LinePlot::to_svg`] or
//! [`Heatmap::to_svg`] (an XML declaration in front of it is removed).
//!
//! Output is deterministic — no timestamps, no random ids: the same report
//! gives byte-identical HTML.
//!
//! [`LinePlot::to_svg`]: crate::LinePlot::to_svg
//! [`Heatmap::to_svg`]: crate::Heatmap::to_svg

use std::path::Path;

use maud::{DOCTYPE, Markup, PreEscaped, html};

use super::section::{Block, ReportSection};
use crate::error::Result;

/// The stylesheet inlined into every report.
const CSS: &str = include_str!("report.css");

/// A table of text cells.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Column headings.
    pub columns: Vec<String>,
    /// Rows of cells; short rows are padded with empty cells. A column whose
    /// non-empty cells all parse as numbers is right-aligned.
    pub rows: Vec<Vec<String>>,
    /// Caption shown above the table (may be empty).
    pub caption: String,
}

impl Table {
    /// A table from column headings, rows and a caption.
    pub fn new(columns: Vec<String>, rows: Vec<Vec<String>>, caption: impl Into<String>) -> Self {
        Table {
            columns,
            rows,
            caption: caption.into(),
        }
    }
}

/// A report under construction; see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    title: String,
    /// Content before the first section (untitled introduction).
    intro: ReportSection,
    /// The numbered sections, in order.
    sections: Vec<ReportSection>,
}

impl Report {
    /// An empty report with a title.
    pub fn new(title: impl Into<String>) -> Self {
        Report {
            title: title.into(),
            intro: ReportSection::default(),
            sections: Vec::new(),
        }
    }

    /// Starts a new numbered section (listed in the table of contents).
    /// Content added before the first section forms an untitled introduction.
    pub fn section(&mut self, heading: impl Into<String>) -> &mut Self {
        self.sections.push(ReportSection::new(heading));
        self
    }

    /// Appends a section built apart ([`ReportSection::append_to`]).
    pub(super) fn push_section(&mut self, section: ReportSection) {
        self.sections.push(section);
    }

    /// The section content goes into: the last one, or the introduction.
    fn current(&mut self) -> &mut ReportSection {
        self.sections.last_mut().unwrap_or(&mut self.intro)
    }

    /// A paragraph of plain text.
    pub fn paragraph(&mut self, text: impl Into<String>) -> &mut Self {
        self.current().paragraph(text);
        self
    }

    /// A numbered table.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.current().table(table);
        self
    }

    /// A two-column list of names and values (e.g. figures of merit).
    pub fn key_values(&mut self, pairs: Vec<(String, String)>) -> &mut Self {
        self.current().key_values(pairs);
        self
    }

    /// A numbered figure: trusted SVG markup (inserted verbatim) and a caption.
    pub fn figure(&mut self, svg: impl Into<String>, caption: impl Into<String>) -> &mut Self {
        self.current().figure(svg, caption);
        self
    }

    /// The complete HTML document.
    pub fn to_html(&self) -> String {
        let groups = self.groups();
        let ids = section_ids(groups.iter().filter_map(|g| g.0));
        let mut counters = Counters::default();
        let body = html! {
            @for (i, (heading, blocks)) in groups.iter().enumerate() {
                @match heading {
                    None => div class="intro" { (render_blocks(blocks, &mut counters)) },
                    Some(h) => {
                        @let n = section_number(&groups, i);
                        @let id = &ids[n - 1];
                        section id=(id) {
                            h2 { span class="num" { (n) } (h) }
                            (render_blocks(blocks, &mut counters))
                        }
                    }
                }
            }
        };
        let doc = html! {
            (DOCTYPE)
            html lang="en" {
                head {
                    meta charset="utf-8";
                    meta name="viewport" content="width=device-width, initial-scale=1";
                    meta name="generator" content="aeromag-report";
                    title { (self.title) }
                    style { (PreEscaped(CSS)) }
                }
                body {
                    header class="top" {
                        div class="wrap" {
                            p class="kicker" { "aeromag report" }
                            h1 { (self.title) }
                        }
                    }
                    main class="wrap" {
                        @if !ids.is_empty() {
                            nav class="toc" {
                                h2 { "Contents" }
                                ol class=[(ids.len() > 6).then_some("cols")] {
                                    @for ((h, _), id) in groups.iter().filter(|g| g.0.is_some()).zip(&ids) {
                                        li { a href={ "#" (id) } { (h.unwrap_or_default()) } }
                                    }
                                }
                            }
                        }
                        (body)
                    }
                    footer class="wrap" {
                        p { "Generated by aeromag. Self-contained file: all figures are inline SVG." }
                    }
                }
            }
        };
        let mut out = line_breaks(&doc.into_string());
        out.push('\n');
        out
    }

    /// Writes [`to_html`](Self::to_html) to `path`, creating missing parent
    /// folders.
    pub fn write_html(&self, path: impl AsRef<Path>) -> Result<()> {
        crate::write_file(path.as_ref(), self.to_html().as_bytes())
    }

    /// Blocks grouped under their section heading (`None` = introduction,
    /// present only when it has content).
    fn groups(&self) -> Vec<(Option<&str>, Vec<&Block>)> {
        let intro =
            (!self.intro.blocks.is_empty()).then(|| (None, self.intro.blocks.iter().collect()));
        intro
            .into_iter()
            .chain(
                self.sections
                    .iter()
                    .map(|s| (Some(s.heading.as_str()), s.blocks.iter().collect())),
            )
            .collect()
    }
}

/// 1-based number of the section in group `i`.
fn section_number(groups: &[(Option<&str>, Vec<&Block>)], i: usize) -> usize {
    groups[..=i].iter().filter(|g| g.0.is_some()).count()
}

/// Unique, URL-friendly ids from headings: lower-case ASCII letters and
/// digits, other runs of characters become `-`; repeats get `-2`, `-3`, ….
fn section_ids<'a>(headings: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for h in headings {
        let mut slug = String::new();
        for c in h.chars() {
            if c.is_ascii_alphanumeric() {
                slug.push(c.to_ascii_lowercase());
            } else if !slug.ends_with('-') && !slug.is_empty() {
                slug.push('-');
            }
        }
        let slug = slug.trim_end_matches('-');
        let base = if slug.is_empty() { "section" } else { slug };
        let mut id = base.to_string();
        let mut k = 2;
        while ids.contains(&id) {
            id = format!("{base}-{k}");
            k += 1;
        }
        ids.push(id);
    }
    ids
}

/// Running figure and table numbers.
#[derive(Default)]
struct Counters {
    figures: usize,
    tables: usize,
}

fn render_blocks(blocks: &[&Block], counters: &mut Counters) -> Markup {
    html! {
        @for b in blocks {
            @match b {
                Block::Paragraph(text) => p { (text) },
                Block::KeyValues(pairs) => table class="kv" {
                    tbody {
                        @for (k, v) in pairs {
                            tr { th scope="row" { (k) } td { (v) } }
                        }
                    }
                },
                Block::Table(t) => {
                    @let n = { counters.tables += 1; counters.tables };
                    (render_table(t, n))
                },
                Block::Figure { svg, caption } => {
                    @let n = { counters.figures += 1; counters.figures };
                    figure id={ "figure-" (n) } {
                        div class="plot" { (PreEscaped(strip_xml_declaration(svg))) }
                        figcaption { b { "Figure " (n) "." } " " (caption) }
                    }
                },
            }
        }
    }
}

fn render_table(t: &Table, n: usize) -> Markup {
    let ncols = t
        .columns
        .len()
        .max(t.rows.iter().map(Vec::len).max().unwrap_or(0));
    // A column is numeric when it has a number and every other non-empty
    // cell is a number or a placeholder such as "—".
    let numeric: Vec<bool> = (0..ncols)
        .map(|c| {
            let cells: Vec<&str> = t
                .rows
                .iter()
                .filter_map(|r| r.get(c))
                .map(|s| s.trim())
                .filter(|s| !s.is_empty())
                .collect();
            let is_number = |s: &str| s.parse::<f64>().is_ok();
            cells.iter().any(|s| is_number(s))
                && cells.iter().all(|s| is_number(s) || is_placeholder(s))
        })
        .collect();
    let class = |c: usize| if numeric[c] { Some("num") } else { None };
    html! {
        div class="table-wrap" {
            table class="data" id={ "table-" (n) } {
                caption { b { "Table " (n) "." } @if !t.caption.is_empty() { " " (t.caption) } }
                thead {
                    tr {
                        @for c in 0..ncols {
                            th scope="col" class=[class(c)] { (t.columns.get(c).map(String::as_str).unwrap_or("")) }
                        }
                    }
                }
                tbody {
                    @for row in &t.rows {
                        tr {
                            @for c in 0..ncols {
                                td class=[class(c)] { (row.get(c).map(String::as_str).unwrap_or("")) }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Starts a new line before the opening tags of block elements and the
/// closing tags of containers
/// so that the page source (and its snapshot) reads line by line. Only the
/// boundary `><` between two tags is touched, which is never inside text
/// (user text is escaped) and where a line break does not change rendering.
fn line_breaks(html: &str) -> String {
    const BLOCK: [&str; 24] = [
        "html",
        "head",
        "meta",
        "title",
        "style",
        "body",
        "header",
        "main",
        "nav",
        "footer",
        "section",
        "div",
        "h1",
        "h2",
        "p",
        "ol",
        "li",
        "table",
        "caption",
        "thead",
        "tbody",
        "tr",
        "figure",
        "figcaption",
    ];
    // Closing tags that get their own line (the others end their line).
    const CONTAINERS: [&str; 14] = [
        "html", "head", "body", "header", "main", "nav", "footer", "section", "div", "ol", "table",
        "thead", "tbody", "figure",
    ];
    let mut out = String::with_capacity(html.len() + html.len() / 16);
    let mut rest = html;
    while let Some(i) = rest.find("><") {
        out.push_str(&rest[..=i]);
        rest = &rest[i + 1..];
        let closing = rest[1..].starts_with('/');
        let name: String = rest[1..]
            .trim_start_matches('/')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect();
        let wanted = if closing { &CONTAINERS[..] } else { &BLOCK[..] };
        if wanted.contains(&name.as_str()) {
            out.push('\n');
        }
    }
    out.push_str(rest);
    out
}

/// Cells that stand for a missing number and do not make a column textual.
fn is_placeholder(s: &str) -> bool {
    matches!(s, "-" | "\u{2013}" | "\u{2014}" | "n/a" | "N/A" | "NA")
}

/// Removes a leading `<?xml …?>` declaration (not allowed inside HTML).
fn strip_xml_declaration(svg: &str) -> &str {
    let s = svg.trim_start();
    if s.starts_with("<?xml")
        && let Some(end) = s.find("?>")
    {
        return s[end + 2..].trim_start();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_slugs_and_unique() {
        let ids = section_ids(
            [
                "Compensation (LS)",
                "Compensation (LS)",
                "Ωмега",
                "  Rotor: model  ",
            ]
            .into_iter(),
        );
        assert_eq!(
            ids,
            vec![
                "compensation-ls",
                "compensation-ls-2",
                "section",
                "rotor-model"
            ]
        );
    }

    #[test]
    fn user_text_is_escaped() {
        let mut r = Report::new("<b>t</b>");
        r.section("A & B").paragraph("x < y").table(Table::new(
            vec!["<script>alert(1)</script>".into()],
            vec![vec!["\"q\"".into()]],
            "c",
        ));
        let html = r.to_html();
        assert!(!html.contains("<script>"));
        assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
        assert!(html.contains("A &amp; B") && html.contains("x &lt; y"));
        assert!(html.contains("<title>&lt;b&gt;t&lt;/b&gt;</title>"));
    }

    #[test]
    fn numeric_columns_are_right_aligned_and_rows_padded() {
        let t = Table::new(
            vec!["name".into(), "rms (nT)".into()],
            vec![
                vec!["ls".into(), "0.12".into()],
                vec!["kalman".into()],
                vec!["x".into(), "—".into()],
            ],
            "",
        );
        let html = render_table(&t, 1).into_string();
        assert!(html.contains("<th scope=\"col\" class=\"num\">rms (nT)</th>"));
        assert!(html.contains("<td class=\"num\">0.12</td>"));
        assert!(html.contains("<td>kalman</td><td class=\"num\"></td>"));
    }

    #[test]
    fn xml_declaration_is_removed() {
        assert_eq!(
            strip_xml_declaration("<?xml version=\"1.0\"?>\n<svg/>"),
            "<svg/>"
        );
        assert_eq!(strip_xml_declaration("<svg/>"), "<svg/>");
    }
}
