//! A small XML writer: elements with attributes, two-space indentation, the
//! five XML specials escaped. It keeps the document well-formed by
//! construction (every `open` has its `close`, checked by [`Xml::finish`]).

use std::fmt::Write;

/// An XML document being written.
#[derive(Debug, Default)]
pub struct Xml {
    out: String,
    open: Vec<&'static str>,
    /// An element was closed that was never opened.
    unbalanced: bool,
}

pub use desc_xml::escape;

impl Xml {
    /// A document starting with the XML declaration (UTF-8).
    pub fn new() -> Self {
        Self {
            out: String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"),
            ..Self::default()
        }
    }

    fn start(&mut self, name: &str, attrs: &[(&str, &str)]) {
        for _ in 0..self.open.len() {
            self.out.push_str("  ");
        }
        self.out.push('<');
        self.out.push_str(name);
        for (k, v) in attrs {
            let _ = write!(self.out, " {k}=\"{}\"", escape(v));
        }
    }

    /// Opens `<name attrs…>`; its children follow until [`Xml::close`].
    pub fn open(&mut self, name: &'static str, attrs: &[(&str, &str)]) {
        self.start(name, attrs);
        self.out.push_str(">\n");
        self.open.push(name);
    }

    /// Writes the empty element `<name attrs…/>`.
    pub fn empty(&mut self, name: &str, attrs: &[(&str, &str)]) {
        self.start(name, attrs);
        self.out.push_str("/>\n");
    }

    /// Writes `<name>text</name>`.
    pub fn text(&mut self, name: &str, text: &str) {
        self.start(name, &[]);
        let _ = writeln!(self.out, ">{}</{name}>", escape(text));
    }

    /// Closes the innermost open element.
    pub fn close(&mut self) {
        match self.open.pop() {
            Some(name) => {
                for _ in 0..self.open.len() {
                    self.out.push_str("  ");
                }
                let _ = writeln!(self.out, "</{name}>");
            }
            None => self.unbalanced = true,
        }
    }

    /// The document, or `None` if an element is still open or was closed
    /// twice.
    pub fn finish(self) -> Option<String> {
        (self.open.is_empty() && !self.unbalanced).then_some(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_nested_elements_and_escapes() {
        let mut x = Xml::new();
        x.open("A", &[("k", "a<b & \"c\"")]);
        x.empty("B", &[]);
        x.text("C", "x>y");
        x.close();
        assert_eq!(
            x.finish().as_deref(),
            Some(
                "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<A k=\"a&lt;b &amp; &quot;c&quot;\">\n  \
                 <B/>\n  <C>x&gt;y</C>\n</A>\n"
            )
        );
        let mut open = Xml::new();
        open.open("A", &[]);
        assert_eq!(open.finish(), None);
        let mut twice = Xml::new();
        twice.close();
        assert_eq!(twice.finish(), None);
    }
}
