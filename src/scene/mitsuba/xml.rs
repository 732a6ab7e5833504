//! Reading Mitsuba XML files into one element tree: `<include>` files spliced in, `<default>`
//! parameters substituted into every attribute (`$name`), `<path>` folders collected, `id`s
//! indexed, and the structure checked (which element may sit inside which, which attributes
//! each element takes). Values are not interpreted here.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};

pub(super) type ElemId = usize;
pub(super) type FileId = usize;

/// Nested `<include>` depth limit (Mitsuba uses the same order of magnitude).
const MAX_INCLUDE_DEPTH: usize = 15;
/// Element nesting limit: real scenes stay far below it, and it keeps the recursive
/// expansion from exhausting the stack on a hostile file.
const MAX_ELEMENT_DEPTH: usize = 64;

/// One XML element that survived expansion (objects, properties, transform operations, refs).
#[derive(Debug)]
pub(super) struct Elem {
    pub tag: String,
    /// Attributes in document order, after `$name` substitution.
    pub attrs: Vec<(String, String)>,
    pub file: FileId,
    /// 1-based line of the element's start tag.
    pub line: u32,
    pub children: Vec<ElemId>,
}

/// The expanded scene: an arena of elements with the root `<scene>` at `root`.
#[derive(Debug)]
pub(super) struct Tree {
    pub elems: Vec<Elem>,
    /// Every XML file read, in order; `files[0]` is the scene file.
    pub files: Vec<PathBuf>,
    pub root: ElemId,
    ids: HashMap<String, ElemId>,
    /// `<alias id="a" as="b"/>`: b → (a, the alias element).
    aliases: HashMap<String, (String, ElemId)>,
    /// `<path>` folders, searched first, the most recently declared first.
    pub path_folders: Vec<PathBuf>,
    /// Remarks about the files read (e.g. a scene version newer than Mitsuba 3).
    pub warnings: Vec<String>,
}

/// What an element is, which decides where it may appear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Scene,
    Object,
    Property,
    Transform,
    TransformOp,
    Ref,
    Include,
    Default,
    Path,
    Alias,
}

fn kind_of(tag: &str) -> Option<Kind> {
    Some(match tag {
        "scene" => Kind::Scene,
        "integrator" | "sensor" | "film" | "rfilter" | "sampler" | "shape" | "bsdf" | "emitter"
        | "texture" | "medium" | "phase" | "volume" => Kind::Object,
        "float" | "integer" | "boolean" | "string" | "rgb" | "spectrum" | "point" | "vector" => {
            Kind::Property
        }
        "transform" => Kind::Transform,
        "translate" | "rotate" | "scale" | "matrix" | "lookat" => Kind::TransformOp,
        "ref" => Kind::Ref,
        "include" => Kind::Include,
        "default" => Kind::Default,
        "path" => Kind::Path,
        "alias" => Kind::Alias,
        _ => return None,
    })
}

/// (allowed attributes, required attributes) of each tag.
fn attribute_rules(tag: &str, kind: Kind) -> (&'static [&'static str], &'static [&'static str]) {
    match kind {
        Kind::Scene => (&["version"], &[]),
        Kind::Object => (&["type", "id", "name"], &["type"]),
        Kind::Transform => (&["name"], &["name"]),
        Kind::Ref => (&["id", "name"], &["id"]),
        Kind::Include => (&["filename"], &["filename"]),
        Kind::Default => (&["name", "value"], &["name", "value"]),
        Kind::Path => (&["value"], &["value"]),
        Kind::Alias => (&["id", "as"], &["id", "as"]),
        Kind::Property => match tag {
            "spectrum" => (&["name", "value", "filename"], &["name"]),
            "point" | "vector" => (&["name", "value", "x", "y", "z"], &["name"]),
            _ => (&["name", "value"], &["name", "value"]),
        },
        Kind::TransformOp => match tag {
            "rotate" => (&["value", "x", "y", "z", "angle"], &["angle"]),
            "matrix" => (&["value"], &["value"]),
            "lookat" => (&["origin", "target", "up"], &["origin", "target"]),
            _ => (&["value", "x", "y", "z"], &[]),
        },
    }
}

impl Tree {
    pub fn elem(&self, id: ElemId) -> &Elem {
        &self.elems[id]
    }

    pub fn tag(&self, id: ElemId) -> &str {
        &self.elems[id].tag
    }

    pub fn attr(&self, id: ElemId, name: &str) -> Option<&str> {
        self.elems[id]
            .attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The `type` attribute of an object element ("" when absent).
    pub fn type_of(&self, id: ElemId) -> &str {
        self.attr(id, "type").unwrap_or("")
    }

    pub fn file_of(&self, id: ElemId) -> &Path {
        &self.files[self.elems[id].file]
    }

    /// The start tag as written, reduced to the attributes that identify it,
    /// e.g. `<bsdf type="diffuse" id="white">`.
    pub fn describe(&self, id: ElemId) -> String {
        let elem = &self.elems[id];
        let mut text = format!("<{}", elem.tag);
        for key in ["type", "name", "id"] {
            if let Some(value) = self.attr(id, key) {
                text.push_str(&format!(" {key}=\"{value}\""));
            }
        }
        text.push('>');
        text
    }

    pub fn location(&self, id: ElemId) -> Location {
        Location::at(self.file_of(id), self.elems[id].line, self.describe(id))
    }

    /// An input error located at element `id`.
    pub fn error(&self, id: ElemId, message: impl Into<String>) -> Error {
        Error::input(self.location(id), message)
    }

    /// A warning naming file, line and element.
    pub fn warning(&self, id: ElemId, message: &str) -> String {
        format!("{}: {message}", self.location(id))
    }

    /// The object a `<ref>` element points at (following aliases). Forward references and
    /// references into other included files work: every file is read before this is asked.
    pub fn resolve_ref(&self, ref_elem: ElemId) -> Result<ElemId> {
        let id = self.attr(ref_elem, "id").unwrap_or("");
        self.lookup(id, ref_elem, 0)
    }

    fn lookup(&self, id: &str, asked_by: ElemId, depth: usize) -> Result<ElemId> {
        if let Some(&elem) = self.ids.get(id) {
            return Ok(elem);
        }
        if let Some((target, alias_elem)) = self.aliases.get(id) {
            if depth > self.aliases.len() {
                return Err(self.error(*alias_elem, format!("alias cycle through id \"{id}\"")));
            }
            return self.lookup(target, *alias_elem, depth + 1);
        }
        Err(self.error(asked_by, format!("reference to unknown id \"{id}\"")))
    }

    /// `resolve_file`, or the message for a file that does not exist:
    /// `{what} "{name}" not found (searched: …)`, every place looked at listed; or, when
    /// the name exists but is no regular file, what it is.
    pub fn find_file(
        &self,
        name: &str,
        named_in: FileId,
        what: &str,
    ) -> std::result::Result<PathBuf, String> {
        let (found, searched) = self.resolve_file(name, named_in);
        found.ok_or_else(|| {
            for path in &searched {
                if let Ok(meta) = std::fs::metadata(path) {
                    let why = crate::io::not_a_file(&meta);
                    return format!("{what} \"{name}\" {why} ({})", path.display());
                }
            }
            let list: Vec<String> = searched.iter().map(|p| p.display().to_string()).collect();
            format!(
                "{what} \"{name}\" not found (searched: {})",
                list.join(", ")
            )
        })
    }

    /// Looks a relative file name up: the `<path>` folders first (most recent first, as
    /// Mitsuba's file resolver does), then the folder of the file that names it, then the
    /// scene file's folder. Absolute names are taken as they are. None when nothing exists.
    pub fn resolve_file(&self, name: &str, named_in: FileId) -> (Option<PathBuf>, Vec<PathBuf>) {
        let name_path = Path::new(name);
        if name_path.is_absolute() {
            let found = name_path.is_file().then(|| name_path.to_path_buf());
            return (found, vec![name_path.to_path_buf()]);
        }
        let mut candidates: Vec<PathBuf> = Vec::new();
        let mut push = |dir: &Path| {
            let candidate = dir.join(name_path);
            if !candidates.contains(&candidate) {
                candidates.push(candidate);
            }
        };
        for folder in &self.path_folders {
            push(folder);
        }
        push(parent_dir(&self.files[named_in]));
        push(parent_dir(&self.files[0]));
        let found = candidates.iter().find(|c| c.is_file()).cloned();
        (found, candidates)
    }
}

fn parent_dir(file: &Path) -> &Path {
    file.parent().unwrap_or(Path::new(""))
}

/// Reads a file as scene text: it must be UTF-8 without NUL bytes.
pub(super) fn read_text(path: &Path) -> Result<String> {
    crate::io::check_input_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let line_at =
        |offset: usize| 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count() as u32;
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        return Err(Error::input(
            Location {
                file: path.to_path_buf(),
                line: Some(line_at(offset)),
                element: None,
            },
            "contains NUL bytes: this is not an XML text file",
        ));
    }
    match std::str::from_utf8(&bytes) {
        Ok(_) => Ok(String::from_utf8(bytes).unwrap_or_default()),
        Err(e) => {
            let offset = e.valid_up_to();
            Err(Error::input(
                Location {
                    file: path.to_path_buf(),
                    line: Some(line_at(offset)),
                    element: None,
                },
                format!("is not valid UTF-8 text (bad byte at offset {offset})"),
            ))
        }
    }
}

/// Builds the expanded tree of the scene `text` read from `path`, with parameters set from
/// outside (Mitsuba's `-D name=value`; none for the file as written): each replaces the value of the scene's `<default name>`; a name the scene does not declare
/// is an error (a misspelt parameter must not be ignored).
pub(super) fn parse_scene_with(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
) -> Result<Tree> {
    if let Some(offset) = text.find('\0') {
        let line = 1 + text[..offset].matches('\n').count() as u32;
        return Err(Error::input(
            Location {
                file: path.to_path_buf(),
                line: Some(line),
                element: None,
            },
            "contains NUL bytes: this is not an XML text file",
        ));
    }
    let mut reader = Reader {
        tree: Tree {
            elems: Vec::new(),
            files: vec![path.to_path_buf()],
            root: 0,
            ids: HashMap::new(),
            aliases: HashMap::new(),
            path_folders: Vec::new(),
            warnings: Vec::new(),
        },
        defaults: overrides.to_vec(),
        declared: Vec::new(),
        include_stack: vec![path.to_path_buf()],
        depth: 0,
    };
    let doc = parse_xml(text, path)?;
    let root = doc.root_element();
    let root_line = doc.text_pos_at(root.range().start).row;
    let root_location = || Location::at(path, root_line, format!("<{}>", root.tag_name().name()));
    if root.tag_name().name() != "scene" {
        return Err(Error::input(
            root_location(),
            "the root element must be <scene>",
        ));
    }
    let attrs = reader.substituted_attrs(&root, path, root_line)?;
    check_attributes(&attrs, "scene", Kind::Scene, root_location)?;
    match attrs.iter().find(|(k, _)| k == "version") {
        None => {
            return Err(Error::input(
                root_location(),
                "missing attribute \"version\" in <scene>",
            ));
        }
        Some((_, version)) => {
            if let Some(w) = check_version(version, root_location)? {
                reader.tree.warnings.push(w);
            }
        }
    }
    reader.tree.elems.push(Elem {
        tag: "scene".into(),
        attrs,
        file: 0,
        line: root_line,
        children: Vec::new(),
    });
    reader.tree.root = 0;
    reader.expand_children(&doc, root, 0, 0, Kind::Scene)?;
    if let Some((name, _)) = overrides
        .iter()
        .find(|(name, _)| !reader.declared.contains(name))
    {
        return Err(Error::input(
            Location::file(path),
            format!(
                "parameter \"{name}\" was set, but the scene declares no <default name=\"{name}\">"
            ),
        ));
    }
    Ok(reader.tree)
}

fn parse_xml<'a>(text: &'a str, path: &Path) -> Result<roxmltree::Document<'a>> {
    roxmltree::Document::parse(text).map_err(|e| {
        Error::input(
            Location {
                file: path.to_path_buf(),
                line: Some(e.pos().row),
                element: None,
            },
            format!("malformed XML: {e}"),
        )
    })
}

/// `version="major.minor.patch"`; scenes older than Mitsuba 2 use other parameter names.
/// A version newer than Mitsuba 3 loads (Mitsuba 3 reads it without a word) with a warning.
fn check_version(version: &str, location: impl Fn() -> Location) -> Result<Option<String>> {
    let parts: Vec<&str> = version.trim().split('.').collect();
    let numbers: Option<Vec<u32>> = parts.iter().map(|p| p.parse().ok()).collect();
    match numbers {
        Some(n) if n.len() == 3 => {
            if n[0] < 2 {
                Err(Error::input(
                    location(),
                    format!(
                        "scene version {version} is a Mitsuba 0.x scene (camelCase parameter \
                         names): convert it to Mitsuba 3 first"
                    ),
                ))
            } else if n[0] > 3 {
                Ok(Some(format!(
                    "{}: scene version {version} is newer than the Mitsuba 3 format mltbench \
                     reads: parameters may have changed meaning",
                    location()
                )))
            } else {
                Ok(None)
            }
        }
        _ => Err(Error::input(
            location(),
            format!("could not parse version \"{version}\" (expected e.g. \"3.0.0\")"),
        )),
    }
}

fn check_attributes(
    attrs: &[(String, String)],
    tag: &str,
    kind: Kind,
    location: impl Fn() -> Location,
) -> Result<()> {
    let (allowed, required) = attribute_rules(tag, kind);
    for (i, (name, _)) in attrs.iter().enumerate() {
        if !allowed.contains(&name.as_str()) {
            return Err(Error::input(
                location(),
                format!("unexpected attribute \"{name}\" in <{tag}>"),
            ));
        }
        if attrs[..i].iter().any(|(other, _)| other == name) {
            return Err(Error::input(
                location(),
                format!("attribute \"{name}\" given twice"),
            ));
        }
    }
    for name in required {
        if !attrs.iter().any(|(k, _)| k == name) {
            return Err(Error::input(
                location(),
                format!("missing attribute \"{name}\" in <{tag}>"),
            ));
        }
    }
    Ok(())
}

struct Reader {
    tree: Tree,
    /// `<default>` parameters in declaration order (the first declaration of a name wins).
    defaults: Vec<(String, String)>,
    /// Names of the `<default>` elements read so far.
    declared: Vec<String>,
    include_stack: Vec<PathBuf>,
    /// Current element nesting depth (includes count as the elements they hold).
    depth: usize,
}

impl Reader {
    /// Attribute values with `$name` replaced by the `<default>` value of `name`. Longer
    /// names are replaced first so that `$ab` is not read as `$a` followed by "b".
    fn substituted_attrs(
        &self,
        node: &roxmltree::Node,
        file: &Path,
        line: u32,
    ) -> Result<Vec<(String, String)>> {
        let mut sorted: Vec<&(String, String)> = self.defaults.iter().collect();
        sorted.sort_by_key(|(name, _)| std::cmp::Reverse(name.len()));
        let mut attrs = Vec::new();
        for attr in node.attributes() {
            let mut value = attr.value().to_string();
            if value.contains('$') {
                for (name, replacement) in &sorted {
                    value = value.replace(&format!("${name}"), replacement);
                }
                if let Some(pos) = value.find('$') {
                    let rest: String = value[pos..].chars().take(32).collect();
                    return Err(Error::input(
                        Location::at(file, line, format!("<{}>", node.tag_name().name())),
                        format!(
                            "undefined parameter \"{rest}\" in attribute \"{}\" (declare it \
                             with <default name=... value=...> before use)",
                            attr.name()
                        ),
                    ));
                }
            }
            attrs.push((attr.name().to_string(), value));
        }
        Ok(attrs)
    }

    /// Expands the children of XML `node` (of `file`) into arena element `parent`, whose kind
    /// is `parent_kind` (for includes: the kind of the element holding the `<include>`).
    fn expand_children(
        &mut self,
        doc: &roxmltree::Document,
        node: roxmltree::Node,
        file: FileId,
        parent: ElemId,
        parent_kind: Kind,
    ) -> Result<()> {
        for child in node.children() {
            if child.is_element() {
                self.expand_element(doc, child, file, parent, parent_kind)?;
            } else if child.is_text() {
                let text = child.text().unwrap_or("");
                if !text.trim().is_empty() {
                    // The line of the first visible character, not of the preceding newline.
                    let range = child.range();
                    let raw = doc.input_text().get(range.clone()).unwrap_or("");
                    let skip = raw.len() - raw.trim_start().len();
                    let line = doc.text_pos_at(range.start + skip).row;
                    let snippet: String = text.trim().chars().take(40).collect();
                    return Err(Error::input(
                        Location {
                            file: self.tree.files[file].clone(),
                            line: Some(line),
                            element: None,
                        },
                        format!("unexpected text \"{snippet}\" (values go in attributes)"),
                    ));
                }
            }
        }
        Ok(())
    }

    fn expand_element(
        &mut self,
        doc: &roxmltree::Document,
        node: roxmltree::Node,
        file: FileId,
        parent: ElemId,
        parent_kind: Kind,
    ) -> Result<()> {
        let tag = node.tag_name().name().to_string();
        let line = doc.text_pos_at(node.range().start).row;
        let file_path = self.tree.files[file].clone();
        let attrs = self.substituted_attrs(&node, &file_path, line)?;
        let location = || {
            let mut text = format!("<{tag}");
            for key in ["type", "name", "id"] {
                if let Some((_, v)) = attrs.iter().find(|(k, _)| k == key) {
                    text.push_str(&format!(" {key}=\"{v}\""));
                }
            }
            text.push('>');
            Location::at(&file_path, line, text)
        };
        let Some(kind) = kind_of(&tag) else {
            return Err(Error::input(location(), format!("unknown element <{tag}>")));
        };
        if self.depth >= MAX_ELEMENT_DEPTH {
            return Err(Error::input(
                location(),
                format!("elements nested deeper than {MAX_ELEMENT_DEPTH} levels"),
            ));
        }
        if tag == "spectrum"
            && let Some((_, plugin)) = attrs.iter().find(|(k, _)| k == "type")
        {
            return Err(Error::input(
                location(),
                format!(
                    "spectrum plugins (type=\"{plugin}\") are not supported yet: give the \
                     spectrum as a value (\"400:0.5, 700:0.8\") or an <rgb>"
                ),
            ));
        }
        check_attributes(&attrs, &tag, kind, location)?;
        check_placement(kind, &tag, parent_kind, location)?;
        let attr = |name: &str| {
            attrs
                .iter()
                .find(|(k, _)| k == name)
                .map(|(_, v)| v.clone())
        };

        match kind {
            Kind::Default => {
                if node.has_children() && node.children().any(|c| c.is_element()) {
                    return Err(Error::input(location(), "<default> cannot have children"));
                }
                let name = attr("name").unwrap_or_default();
                if name.is_empty() {
                    return Err(Error::input(location(), "<default> needs a non-empty name"));
                }
                self.declared.push(name.clone());
                if !self.defaults.iter().any(|(n, _)| *n == name) {
                    self.defaults
                        .push((name, attr("value").unwrap_or_default()));
                }
                Ok(())
            }
            Kind::Path => {
                let value = attr("value").unwrap_or_default();
                let folder = parent_dir(&file_path).join(&value);
                if !folder.is_dir() {
                    return Err(Error::input(
                        location(),
                        format!("<path>: folder \"{}\" not found", folder.display()),
                    ));
                }
                self.tree.path_folders.insert(0, folder);
                Ok(())
            }
            Kind::Alias => {
                let (source, alias) = (
                    attr("id").unwrap_or_default(),
                    attr("as").unwrap_or_default(),
                );
                let elem = self.push_elem(tag.clone(), attrs.clone(), file, line, None);
                if self.tree.ids.contains_key(&alias) || self.tree.aliases.contains_key(&alias) {
                    return Err(Error::input(
                        location(),
                        format!("duplicate id \"{alias}\""),
                    ));
                }
                self.tree.aliases.insert(alias, (source, elem));
                Ok(())
            }
            Kind::Include => self.include(
                &attr("filename").unwrap_or_default(),
                file,
                parent,
                parent_kind,
                location,
            ),
            Kind::Scene => Err(Error::input(
                location(),
                "<scene> can only be the root element",
            )),
            Kind::Object | Kind::Property | Kind::Transform | Kind::TransformOp | Kind::Ref => {
                let id_attr = if kind == Kind::Object {
                    attr("id")
                } else {
                    None
                };
                let elem = self.push_elem(tag.clone(), attrs.clone(), file, line, Some(parent));
                if let Some(id) = id_attr {
                    if let Some(&previous) = self.tree.ids.get(&id) {
                        let prev = self.tree.location(previous);
                        return Err(Error::input(
                            location(),
                            format!("duplicate id \"{id}\" (first defined at {prev})"),
                        ));
                    }
                    if self.tree.aliases.contains_key(&id) {
                        return Err(Error::input(location(), format!("duplicate id \"{id}\"")));
                    }
                    self.tree.ids.insert(id, elem);
                }
                self.depth += 1;
                let result = match kind {
                    Kind::Object | Kind::Transform => {
                        self.expand_children(doc, node, file, elem, kind)
                    }
                    _ => {
                        if let Some(child) = node.children().find(|c| c.is_element()) {
                            let child_line = doc.text_pos_at(child.range().start).row;
                            return Err(Error::input(
                                Location::at(
                                    &file_path,
                                    child_line,
                                    format!("<{}>", child.tag_name().name()),
                                ),
                                format!("<{tag}> cannot contain other elements"),
                            ));
                        }
                        self.expand_children(doc, node, file, elem, kind)
                    }
                };
                self.depth -= 1;
                result
            }
        }
    }

    fn push_elem(
        &mut self,
        tag: String,
        attrs: Vec<(String, String)>,
        file: FileId,
        line: u32,
        parent: Option<ElemId>,
    ) -> ElemId {
        let id = self.tree.elems.len();
        self.tree.elems.push(Elem {
            tag,
            attrs,
            file,
            line,
            children: Vec::new(),
        });
        if let Some(parent) = parent {
            self.tree.elems[parent].children.push(id);
        }
        id
    }

    fn include(
        &mut self,
        filename: &str,
        file: FileId,
        parent: ElemId,
        parent_kind: Kind,
        location: impl Fn() -> Location,
    ) -> Result<()> {
        let path = self
            .tree
            .find_file(filename, file, "included file")
            .map_err(|message| Error::input(location(), message))?;
        let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
        if self
            .include_stack
            .iter()
            .any(|p| p.canonicalize().unwrap_or_else(|_| p.clone()) == canonical)
        {
            return Err(Error::input(
                location(),
                format!("\"{}\" includes itself (include cycle)", path.display()),
            ));
        }
        if self.include_stack.len() > MAX_INCLUDE_DEPTH {
            return Err(Error::input(
                location(),
                format!("includes nested deeper than {MAX_INCLUDE_DEPTH} levels"),
            ));
        }
        let text = read_text(&path)?;
        let doc = parse_xml(&text, &path)?;
        let new_file = self.tree.files.len();
        self.tree.files.push(path.clone());
        self.include_stack.push(path.clone());
        let root = doc.root_element();
        if root.tag_name().name() == "scene" {
            let line = doc.text_pos_at(root.range().start).row;
            let attrs = self.substituted_attrs(&root, &path, line)?;
            let root_location = || Location::at(&path, line, "<scene>");
            check_attributes(&attrs, "scene", Kind::Scene, root_location)?;
            if let Some((_, version)) = attrs.iter().find(|(k, _)| k == "version")
                && let Some(w) = check_version(version, root_location)?
            {
                self.tree.warnings.push(w);
            }
            self.expand_children(&doc, root, new_file, parent, parent_kind)?;
        } else {
            self.expand_element(&doc, root, new_file, parent, parent_kind)?;
        }
        self.include_stack.pop();
        Ok(())
    }
}

/// Which kinds of element may appear inside which (Mitsuba's rules).
fn check_placement(
    kind: Kind,
    tag: &str,
    parent_kind: Kind,
    location: impl Fn() -> Location,
) -> Result<()> {
    let ok = match parent_kind {
        Kind::Transform => kind == Kind::TransformOp,
        Kind::Scene => matches!(
            kind,
            Kind::Object | Kind::Ref | Kind::Include | Kind::Default | Kind::Path | Kind::Alias
        ),
        Kind::Object => matches!(
            kind,
            Kind::Object
                | Kind::Property
                | Kind::Transform
                | Kind::Ref
                | Kind::Include
                | Kind::Default
                | Kind::Alias
        ),
        _ => false,
    };
    if ok {
        return Ok(());
    }
    let message = match (kind, parent_kind) {
        (Kind::TransformOp, _) => format!("<{tag}> can only appear inside <transform>"),
        (_, Kind::Transform) => {
            format!(
                "<transform> can only contain translate, rotate, scale, matrix and lookat, not <{tag}>"
            )
        }
        (Kind::Path, _) => "<path> can only appear directly inside <scene>".to_string(),
        (Kind::Property | Kind::Transform, Kind::Scene) => {
            format!("<{tag}> (a parameter) cannot appear directly inside <scene>")
        }
        _ => format!("<{tag}> cannot appear here"),
    };
    Err(Error::input(location(), message))
}
