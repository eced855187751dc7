//! The MSH 4.1 ASCII reader: tokens with their lines, and one method per section.

use super::*;

/// Whitespace-separated tokens with their 1-based line; a double-quoted string (a
/// physical name) is one token, quotes included.
pub(super) fn tokenize(text: &str) -> Vec<(&str, usize)> {
    let mut out = Vec::new();
    for (l, line) in text.lines().enumerate() {
        let mut rest = line;
        loop {
            rest = rest.trim_start();
            if rest.is_empty() {
                break;
            }
            let end = if let Some(after) = rest.strip_prefix('"') {
                after.find('"').map_or(rest.len(), |i| i + 2)
            } else {
                rest.find(char::is_whitespace).unwrap_or(rest.len())
            };
            out.push((&rest[..end], l + 1));
            rest = &rest[end..];
        }
    }
    out
}

pub(super) struct Parser<'a> {
    pub(super) toks: Vec<(&'a str, usize)>,
    pub(super) pos: usize,
    pub(super) file: &'a Path,
    pub(super) last_line: usize,
}

impl<'a> Parser<'a> {
    pub(super) fn err(
        &self,
        line: Option<usize>,
        problem: String,
        expected: impl Into<String>,
    ) -> IoError {
        IoError::Msh {
            file: self.file.to_path_buf(),
            line,
            problem,
            expected: expected.into(),
        }
    }

    /// The next token; at the end of the file an error saying what was expected.
    pub(super) fn next(&mut self, what: &str) -> Result<(&'a str, usize), IoError> {
        match self.toks.get(self.pos) {
            Some(&t) => {
                self.pos += 1;
                Ok(t)
            }
            None => Err(self.err(
                Some(self.last_line),
                "the file ends early (truncated?)".into(),
                what.to_string(),
            )),
        }
    }

    pub(super) fn peek(&self) -> Option<(&'a str, usize)> {
        self.toks.get(self.pos).copied()
    }

    pub(super) fn int(&mut self, what: &str) -> Result<(i64, usize), IoError> {
        let (t, line) = self.next(what)?;
        t.parse::<i64>()
            .map(|v| (v, line))
            .map_err(|_| self.err(Some(line), format!("`{t}` is not an integer"), what))
    }

    /// A count or tag (>= 0).
    pub(super) fn count(&mut self, what: &str) -> Result<(usize, usize), IoError> {
        let (v, line) = self.int(what)?;
        usize::try_from(v)
            .map(|v| (v, line))
            .map_err(|_| self.err(Some(line), format!("`{v}` is negative"), what))
    }

    pub(super) fn real(&mut self, what: &str) -> Result<f64, IoError> {
        let (t, line) = self.next(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.err(Some(line), format!("`{t}` is not a finite number"), what)),
        }
    }

    pub(super) fn expect(&mut self, tok: &str) -> Result<(), IoError> {
        let (t, line) = self.next(&format!("`{tok}`"))?;
        if t == tok {
            Ok(())
        } else {
            Err(self.err(Some(line), format!("found `{t}`"), format!("`{tok}`")))
        }
    }
}

/// One `$Elements` block, kept until `$Entities` is known.
pub(super) struct Block {
    pub(super) dim: usize,
    pub(super) tag: i64,
    /// (element tag, line, node tags).
    pub(super) elements: Vec<(u64, usize, Vec<u64>)>,
    pub(super) hex: bool,
}

/// The sections of an MSH 4.1 file, each read by its own method.
impl Parser<'_> {
    /// `$MeshFormat`: version 4.1, ASCII.
    pub(super) fn mesh_format(&mut self) -> Result<(), IoError> {
        match self.peek() {
            Some(("$MeshFormat", _)) => self.pos += 1,
            Some((t, line)) => {
                return Err(self.err(
                    Some(line),
                    format!("found `{t}` where the file should start with `$MeshFormat`"),
                    EXPECTED_FORMAT,
                ))
            }
            None => return Err(self.err(Some(1), "the file is empty".into(), EXPECTED_FORMAT)),
        }
        let (version, vline) = self.next("the format version `4.1`")?;
        let (ftype, _) = self.next("the file type `0` (ASCII)")?;
        if version != "4.1" {
            return Err(self.err(
                Some(vline),
                format!("MSH version `{version}` is not read"),
                EXPECTED_FORMAT,
            ));
        }
        if ftype != "0" {
            return Err(self.err(
                Some(vline),
                format!("file type `{ftype}` (binary) is not read"),
                EXPECTED_FORMAT,
            ));
        }
        self.next("the data size (8)")?;
        self.expect("$EndMeshFormat")?;
        Ok(())
    }

    /// `$PhysicalNames` into `names` (by dimension and physical tag).
    pub(super) fn physical_names(
        &mut self,
        names: &mut HashMap<(usize, i64), String>,
    ) -> Result<(), IoError> {
        let (n, _) = self.count("the number of physical names")?;
        for _ in 0..n {
            let (dim, dline) = self.count("a physical dimension (0 to 3)")?;
            if dim > 3 {
                return Err(self.err(
                    Some(dline),
                    format!("physical dimension {dim}"),
                    "a dimension 0 to 3",
                ));
            }
            let (tag, _) = self.int("a physical tag")?;
            let (name, nline) = self.next("a quoted physical name")?;
            let unq = name
                .strip_prefix('"')
                .and_then(|s| s.strip_suffix('"'))
                .ok_or_else(|| {
                    self.err(
                        Some(nline),
                        format!("physical name {name} is not quoted"),
                        "a name in double quotes",
                    )
                })?;
            names.insert((dim, tag), unq.to_string());
        }
        self.expect("$EndPhysicalNames")?;
        Ok(())
    }

    /// `$Entities`: the physical tags of every entity, into `entity_phys`.
    pub(super) fn entities(
        &mut self,
        entity_phys: &mut HashMap<(usize, i64), Vec<i64>>,
    ) -> Result<(), IoError> {
        let mut counts = [0usize; 4];
        for c in counts.iter_mut() {
            *c = self
                .count("the numbers of points, curves, surfaces and volumes")?
                .0;
        }
        for (dim, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let (tag, _) = self.int("an entity tag")?;
                // a point has X Y Z, the others a bounding box
                for _ in 0..if dim == 0 { 3 } else { 6 } {
                    self.real("entity coordinates")?;
                }
                let (np, _) = self.count("the number of physical tags")?;
                let mut phys = Vec::with_capacity(np.min(64));
                for _ in 0..np {
                    phys.push(self.int("a physical tag")?.0);
                }
                if dim > 0 {
                    let (nb, _) = self.count("the number of bounding entities")?;
                    for _ in 0..nb {
                        self.int("a bounding entity tag")?;
                    }
                }
                entity_phys.insert((dim, tag), phys);
            }
        }
        self.expect("$EndEntities")?;
        Ok(())
    }

    /// `$Nodes` into `nodes` (by node tag).
    pub(super) fn nodes(&mut self, nodes: &mut HashMap<u64, [f64; 3]>) -> Result<(), IoError> {
        let (nb, _) = self.count("the number of node entity blocks")?;
        let (total, tline) = self.count("the number of nodes")?;
        self.count("the minimum node tag")?;
        self.count("the maximum node tag")?;
        let mut found = 0usize;
        for _ in 0..nb {
            let (dim, _) = self.count("the entity dimension of a node block")?;
            self.int("the entity tag of a node block")?;
            let (param, pline) = self.count("the parametric flag (0 or 1)")?;
            if param > 1 || dim > 3 {
                return Err(self.err(
                    Some(pline),
                    format!("node block of dimension {dim} with parametric flag {param}"),
                    "a node block header `entityDim(0-3) entityTag parametric(0/1) numNodes`",
                ));
            }
            let (n, _) = self.count("the number of nodes in the block")?;
            let mut tags = Vec::with_capacity(n.min(1 << 20));
            for _ in 0..n {
                let (t, l) = self.count("a node tag")?;
                tags.push((t as u64, l));
            }
            for (t, l) in tags {
                let x = [
                    self.real("node coordinates x y z")?,
                    self.real("node coordinates x y z")?,
                    self.real("node coordinates x y z")?,
                ];
                for _ in 0..param * dim {
                    self.real("parametric node coordinates")?;
                }
                if nodes.insert(t, x).is_some() {
                    return Err(self.err(
                        Some(l),
                        format!("node tag {t} is defined twice"),
                        "each node tag defined once",
                    ));
                }
            }
            found += n;
        }
        if found != total {
            return Err(self.err(
                Some(tline),
                format!("the header declares {total} nodes, the blocks hold {found}"),
                "numNodes equal to the sum of the blocks' node counts",
            ));
        }
        self.expect("$EndNodes")?;
        Ok(())
    }

    /// `$Elements` into `blocks` (only points, lines, quadrangles and hexahedra).
    pub(super) fn elements(&mut self, blocks: &mut Vec<Block>) -> Result<(), IoError> {
        let (nb, _) = self.count("the number of element entity blocks")?;
        let (total, tline) = self.count("the number of elements")?;
        self.count("the minimum element tag")?;
        self.count("the maximum element tag")?;
        let mut found = 0usize;
        for _ in 0..nb {
            let (dim, dline) = self.count("the entity dimension of an element block")?;
            let (tag, _) = self.int("the entity tag of an element block")?;
            let (ty, tyline) = self.int("the element type")?;
            let (n, _) = self.count("the number of elements in the block")?;
            let Some((name, nn, tdim)) = element_type(ty) else {
                return Err(self.err(
                    Some(tyline),
                    format!("unknown element type {ty}"),
                    EXPECTED_HEX,
                ));
            };
            if ![1, 3, 5, 15].contains(&ty) {
                return Err(self.err(
                    Some(tyline),
                    format!("element type {ty} ({name}) in entity {tag} of dimension {tdim}"),
                    EXPECTED_HEX,
                ));
            }
            if dim != tdim {
                return Err(self.err(
                    Some(dline),
                    format!("a block of entity dimension {dim} holds {name}s (dimension {tdim})"),
                    "element blocks whose entity dimension matches the element type",
                ));
            }
            let mut elements = Vec::with_capacity(n.min(1 << 20));
            for _ in 0..n {
                let (etag, eline) = self.count("an element tag")?;
                let mut v = Vec::with_capacity(nn);
                for _ in 0..nn {
                    if self.peek().is_none_or(|(_, l)| l != eline) {
                        return Err(self.err(
                            Some(eline),
                            format!("element {etag} has fewer than {nn} node tags"),
                            format!("`elementTag` and {nn} node tags on one line"),
                        ));
                    }
                    let (t, _) = self.count(&format!("{nn} node tags of a {name}"))?;
                    v.push(t as u64);
                }
                if self.peek().is_some_and(|(_, l)| l == eline) {
                    return Err(self.err(
                        Some(eline),
                        format!("element {etag} has more than {nn} node tags"),
                        format!("`elementTag` and {nn} node tags on one line"),
                    ));
                }
                elements.push((etag as u64, eline, v));
            }
            found += n;
            blocks.push(Block {
                dim,
                tag,
                elements,
                hex: ty == 5,
            });
        }
        if found != total {
            return Err(self.err(
                Some(tline),
                format!("the header declares {total} elements, the blocks hold {found}"),
                "numElements equal to the sum of the blocks' element counts",
            ));
        }
        self.expect("$EndElements")?;
        Ok(())
    }

    /// Skips a section `s` the reader does not use (opened on `line`).
    pub(super) fn skip_section(&mut self, s: &str, line: usize) -> Result<(), IoError> {
        let end = format!("$End{}", &s[1..]);
        loop {
            match self.peek() {
                Some((t, _)) if t == end => {
                    self.pos += 1;
                    break;
                }
                Some(_) => self.pos += 1,
                None => {
                    return Err(self.err(
                        Some(line),
                        format!("section `{s}` is not closed (truncated?)"),
                        format!("`{end}`"),
                    ))
                }
            }
        }
        Ok(())
    }
}
