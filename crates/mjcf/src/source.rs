//! XML text → an owned element tree with `<include>` expanded. This is the purely syntactic
//! layer: element names, attribute strings and where each was written.

use std::path::{Path, PathBuf};

use crate::error::{Error, Location};

/// A byte offset into one of the loaded files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Pos {
    pub file: u32,
    pub offset: u32,
}

/// All files read for one model (the main file first, then includes in reading order).
#[derive(Debug, Default)]
pub(crate) struct Sources {
    files: Vec<(String, String)>,
}

impl Sources {
    pub(crate) fn add(&mut self, name: String, text: String) -> u32 {
        self.files.push((name, text));
        u32::try_from(self.files.len() - 1).unwrap_or(u32::MAX)
    }

    pub fn main_name(&self) -> String {
        self.files.first().map(|f| f.0.clone()).unwrap_or_default()
    }

    /// `line:column` (1-based, columns in characters) of a position: the error path only.
    pub fn locate(&self, pos: Pos) -> Location {
        let Some((name, text)) = self.files.get(pos.file as usize) else {
            return Location { file: self.main_name(), line: 0, column: 0 };
        };
        let end = (pos.offset as usize).min(text.len());
        let before = text.get(..end).unwrap_or("");
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before[line_start..].chars().count() + 1;
        Location { file: name.clone(), line: to_u32(line), column: to_u32(column) }
    }

    pub fn invalid(&self, pos: Pos, message: impl Into<String>) -> Error {
        Error::Invalid { at: self.locate(pos), message: message.into() }
    }

    pub fn unsupported(&self, pos: Pos, message: impl Into<String>) -> Error {
        Error::Unsupported { at: self.locate(pos), message: message.into() }
    }
}

fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

#[derive(Debug, Clone)]
pub(crate) struct Attr {
    pub name: String,
    pub value: String,
    pub pos: Pos,
}

/// One XML element, owned, with `<include>` already replaced by the included file's content.
#[derive(Debug, Clone)]
pub(crate) struct Element {
    pub name: String,
    pub attrs: Vec<Attr>,
    pub children: Vec<Element>,
    pub pos: Pos,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }
}

/// Nested includes deeper than this are reported as an include cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// Reads the root `<mujoco>` element of `text` and everything it includes.
pub(crate) fn load(
    name: String,
    text: String,
    base_dir: Option<&Path>,
    sources: &mut Sources,
) -> Result<Element, Error> {
    let loader = Loader { base_dir: base_dir.map(Path::to_path_buf) };
    let file = sources.add(name, text);
    let root = loader.parse_file(file, sources, 0)?;
    if root.name != "mujoco" {
        return Err(sources
            .invalid(root.pos, format!("root element is <{}>, expected <mujoco>", root.name)));
    }
    Ok(root)
}

struct Loader {
    base_dir: Option<PathBuf>,
}

impl Loader {
    fn parse_file(&self, file: u32, sources: &mut Sources, depth: usize) -> Result<Element, Error> {
        let (name, text) = sources.files.get(file as usize).cloned().unwrap_or_default();
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
            let p = e.pos();
            let at = Location { file: name.clone(), line: p.row, column: p.col };
            Error::Xml { at, message: e.to_string() }
        })?;
        self.convert(doc.root_element(), file, sources, depth)
    }

    fn convert(
        &self,
        node: roxmltree::Node<'_, '_>,
        file: u32,
        sources: &mut Sources,
        depth: usize,
    ) -> Result<Element, Error> {
        let pos = |offset: usize| Pos { file, offset: to_u32(offset) };
        let attrs = node
            .attributes()
            .map(|a| Attr {
                name: a.name().to_owned(),
                value: a.value().to_owned(),
                pos: pos(a.range().start),
            })
            .collect();
        let mut element = Element {
            name: node.tag_name().name().to_owned(),
            attrs,
            children: Vec::new(),
            pos: pos(node.range().start),
        };
        for child in node.children().filter(roxmltree::Node::is_element) {
            let converted = self.convert(child, file, sources, depth)?;
            if converted.name == "include" {
                element.children.extend(self.include(&converted, sources, depth + 1)?);
            } else {
                element.children.push(converted);
            }
        }
        Ok(element)
    }

    /// `<include file="..."/>`: the children of the included file's `<mujoco>` root, in place.
    /// Paths are relative to the directory of the main model file, as in MuJoCo.
    fn include(
        &self,
        inc: &Element,
        sources: &mut Sources,
        depth: usize,
    ) -> Result<Vec<Element>, Error> {
        let Some(file_attr) = inc.attr("file") else {
            return Err(sources.invalid(inc.pos, "<include> without a file attribute"));
        };
        if depth > MAX_INCLUDE_DEPTH {
            return Err(sources.invalid(
                inc.pos,
                format!("includes nested deeper than {MAX_INCLUDE_DEPTH} (include cycle?)"),
            ));
        }
        let path = match &self.base_dir {
            Some(dir) => dir.join(&file_attr.value),
            None => PathBuf::from(&file_attr.value),
        };
        let text = std::fs::read_to_string(&path).map_err(|e| {
            sources.invalid(
                file_attr.pos,
                format!("cannot read included file {}: {e}", path.display()),
            )
        })?;
        let file = sources.add(path.display().to_string(), text);
        let root = self.parse_file(file, sources, depth)?;
        if root.name != "mujoco" {
            return Err(sources.invalid(
                root.pos,
                format!("root element of an included file is <{}>, expected <mujoco>", root.name),
            ));
        }
        Ok(root.children)
    }
}
