//! A report section built by one command and appended to another command's
//! report (`aeromag demo` collects the sections of `em study`, `rotor study`).

use aeromag_report::{Report, Table};

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
}

/// A heading and its blocks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReportSection {
    /// Section heading.
    pub heading: String,
    /// Content in order.
    pub blocks: Vec<Block>,
}

impl ReportSection {
    /// Empty section with a heading.
    pub fn new(heading: impl Into<String>) -> Self {
        Self {
            heading: heading.into(),
            blocks: Vec::new(),
        }
    }

    /// Append the section to `r`.
    pub fn append_to(self, r: &mut Report) {
        r.section(self.heading);
        for b in self.blocks {
            match b {
                Block::Paragraph(p) => {
                    r.paragraph(p);
                }
                Block::Figure { svg, caption } => {
                    r.figure(svg, caption);
                }
                Block::Table(t) => {
                    r.table(t);
                }
            }
        }
    }
}
