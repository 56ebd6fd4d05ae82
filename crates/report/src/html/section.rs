//! A report section built apart from the [`Report`] it goes into: a study
//! builds its section, and whoever assembles the report appends it (the
//! demo collects the sections of every study).

use super::report::{Report, Table};

/// One element of a [`ReportSection`], in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A paragraph of text.
    Paragraph(String),
    /// An inline SVG figure with its caption.
    Figure {
        /// The SVG document.
        svg: String,
        /// Caption under the figure.
        caption: String,
    },
    /// A table.
    Table(Table),
    /// A list of names and values.
    KeyValues(Vec<(String, String)>),
}

/// A heading and its blocks.
///
/// ```
/// use aeromag_report::{Report, ReportSection};
/// let mut s = ReportSection::new("Rotor");
/// s.paragraph("The model leaves 0.12 nT.");
/// let mut r = Report::new("demo");
/// s.append_to(&mut r);
/// assert!(r.to_html().contains("0.12 nT"));
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReportSection {
    /// Section heading.
    pub heading: String,
    /// Content in order.
    pub blocks: Vec<Block>,
}

impl ReportSection {
    /// An empty section with a heading.
    pub fn new(heading: impl Into<String>) -> Self {
        Self {
            heading: heading.into(),
            blocks: Vec::new(),
        }
    }

    /// Add a paragraph.
    pub fn paragraph(&mut self, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Paragraph(text.into()));
        self
    }

    /// Add an SVG figure with its caption.
    pub fn figure(&mut self, svg: impl Into<String>, caption: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Figure {
            svg: svg.into(),
            caption: caption.into(),
        });
        self
    }

    /// Add a table.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.blocks.push(Block::Table(table));
        self
    }

    /// Add a list of names and values.
    pub fn key_values(&mut self, pairs: Vec<(String, String)>) -> &mut Self {
        self.blocks.push(Block::KeyValues(pairs));
        self
    }

    /// Append the section to `r`.
    pub fn append_to(self, r: &mut Report) {
        r.push_section(self);
    }
}
