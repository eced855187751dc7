//! Gmsh MSH 4.1 ASCII meshes of 8-node hexahedra: [`read_msh`] and [`write_msh`].
//!
//! **What is read.** `$MeshFormat` must be `4.1 0 <size>` (ASCII). `$PhysicalNames`,
//! `$Entities`, `$Nodes` and `$Elements` are read; every other section (`$Periodic`,
//! `$NodeData`, `$PartitionedEntities`, ...) is skipped. Node tags may be sparse and
//! need not be sorted; parametric node blocks are accepted (the parametric coordinates
//! are ignored). Element types: 5 (8-node hexahedron) makes the mesh; 3 (4-node
//! quadrangle), 1 (2-node line) and 15 (point) only carry physical groups. Any other
//! type is an error naming it (a tetrahedron, prism, pyramid or second-order element
//! cannot be analysed by squeal's trilinear hexahedra).
//!
//! **Node order.** Gmsh numbers a hexahedron's nodes like VTK and like squeal
//! ([`squeal_fe::mesh`]): nodes 0-3 on the bottom face counter-clockwise seen from the
//! top, nodes 4-7 above them. No reordering is needed. An element whose volume
//! ([`squeal_fe::mesh::hex_volume`]) is negative (a mirrored node order, as some
//! exporters write) is flipped to `[0, 3, 2, 1, 4, 7, 6, 5]`; a degenerate one (zero
//! volume to `1e-12` of its largest edge cubed) is an error naming its element tag.
//!
//! **Output.** A [`Mesh`] with every hexahedron in body 0 and the nodes used by them
//! (others are dropped), numbered in increasing node tag order. Every physical group of
//! dimension 0 to 2 becomes a node set named after its physical name (`physical_<tag>`
//! when unnamed) holding the sorted nodes of its elements; groups of different
//! dimensions with one name are merged. Physical volumes (which Gmsh needs to save the
//! hexahedra at all) select nothing: every hexahedron of the file is read. Coordinates are returned as written (the caller scales them).
//!
//! Every error ([`IoError::Msh`]) names the file, the 1-based line where one applies and
//! what was expected; malformed input never panics.

use crate::IoError;
use squeal_fe::mesh::hex_volume;
use squeal_fe::Mesh;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The expected format, quoted in errors.
const EXPECTED_FORMAT: &str = "MSH 4.1 ASCII (`$MeshFormat` then `4.1 0 8`; \
                               export with `gmsh -format msh41` and Mesh.Binary = 0)";

/// What a hexahedral mesh file must contain, quoted in element-type errors.
const EXPECTED_HEX: &str = "8-node hexahedra (type 5), with 4-node quadrangles (3), \
                            lines (1) or points (15) for physical groups";

/// Name and node count of a Gmsh element type.
fn element_type(t: i64) -> Option<(&'static str, usize, usize)> {
    // (name, nodes, dimension)
    Some(match t {
        1 => ("2-node line", 2, 1),
        2 => ("3-node triangle", 3, 2),
        3 => ("4-node quadrangle", 4, 2),
        4 => ("4-node tetrahedron", 4, 3),
        5 => ("8-node hexahedron", 8, 3),
        6 => ("6-node prism", 6, 3),
        7 => ("5-node pyramid", 5, 3),
        8 => ("3-node line", 3, 1),
        9 => ("6-node triangle", 6, 2),
        10 => ("9-node quadrangle", 9, 2),
        11 => ("10-node tetrahedron", 10, 3),
        12 => ("27-node hexahedron", 27, 3),
        13 => ("18-node prism", 18, 3),
        14 => ("14-node pyramid", 14, 3),
        15 => ("1-node point", 1, 0),
        16 => ("8-node quadrangle", 8, 2),
        17 => ("20-node hexahedron", 20, 3),
        18 => ("15-node prism", 15, 3),
        19 => ("13-node pyramid", 13, 3),
        _ => return None,
    })
}

/// Whitespace-separated tokens with their 1-based line; a double-quoted string (a
/// physical name) is one token, quotes included.
fn tokenize(text: &str) -> Vec<(&str, usize)> {
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

struct Parser<'a> {
    toks: Vec<(&'a str, usize)>,
    pos: usize,
    file: &'a Path,
    last_line: usize,
}

impl<'a> Parser<'a> {
    fn err(&self, line: Option<usize>, problem: String, expected: impl Into<String>) -> IoError {
        IoError::Msh {
            file: self.file.to_path_buf(),
            line,
            problem,
            expected: expected.into(),
        }
    }

    /// The next token; at the end of the file an error saying what was expected.
    fn next(&mut self, what: &str) -> Result<(&'a str, usize), IoError> {
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

    fn peek(&self) -> Option<(&'a str, usize)> {
        self.toks.get(self.pos).copied()
    }

    fn int(&mut self, what: &str) -> Result<(i64, usize), IoError> {
        let (t, line) = self.next(what)?;
        t.parse::<i64>()
            .map(|v| (v, line))
            .map_err(|_| self.err(Some(line), format!("`{t}` is not an integer"), what))
    }

    /// A count or tag (>= 0).
    fn count(&mut self, what: &str) -> Result<(usize, usize), IoError> {
        let (v, line) = self.int(what)?;
        usize::try_from(v)
            .map(|v| (v, line))
            .map_err(|_| self.err(Some(line), format!("`{v}` is negative"), what))
    }

    fn real(&mut self, what: &str) -> Result<f64, IoError> {
        let (t, line) = self.next(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.err(Some(line), format!("`{t}` is not a finite number"), what)),
        }
    }

    fn expect(&mut self, tok: &str) -> Result<(), IoError> {
        let (t, line) = self.next(&format!("`{tok}`"))?;
        if t == tok {
            Ok(())
        } else {
            Err(self.err(Some(line), format!("found `{t}`"), format!("`{tok}`")))
        }
    }
}

/// One `$Elements` block, kept until `$Entities` is known.
struct Block {
    dim: usize,
    tag: i64,
    /// (element tag, line, node tags).
    elements: Vec<(u64, usize, Vec<u64>)>,
    hex: bool,
}

/// Reads a Gmsh MSH 4.1 ASCII file of 8-node hexahedra (see the [module docs](self)).
pub fn read_msh(path: &Path) -> Result<Mesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        file: path.to_path_buf(),
        action: "read",
        source,
    })?;
    read_msh_bytes(&bytes, path)
}

/// Reads MSH 4.1 ASCII content; `file` names it in errors.
pub fn read_msh_bytes(bytes: &[u8], file: &Path) -> Result<Mesh, IoError> {
    let text = String::from_utf8_lossy(bytes);
    let toks = tokenize(&text);
    let last_line = toks.last().map_or(1, |t| t.1);
    let mut p = Parser {
        toks,
        pos: 0,
        file,
        last_line,
    };
    p.mesh_format()?;
    let mut names: HashMap<(usize, i64), String> = HashMap::new();
    let mut entity_phys: HashMap<(usize, i64), Vec<i64>> = HashMap::new();
    let mut nodes: HashMap<u64, [f64; 3]> = HashMap::new();
    let mut blocks: Vec<Block> = Vec::new();
    let (mut seen_nodes, mut seen_elements) = (false, false);
    while let Some((sec, line)) = p.peek() {
        p.pos += 1;
        match sec {
            "$PhysicalNames" => p.physical_names(&mut names)?,
            "$Entities" => p.entities(&mut entity_phys)?,
            "$Nodes" => {
                seen_nodes = true;
                p.nodes(&mut nodes)?;
            }
            "$Elements" => {
                seen_elements = true;
                p.elements(&mut blocks)?;
            }
            s if s.starts_with('$') && !s.starts_with("$End") => p.skip_section(s, line)?,
            other => {
                return Err(p.err(
                    Some(line),
                    format!("found `{other}` between sections"),
                    "a section such as `$Nodes` ... `$EndNodes`",
                ))
            }
        }
    }
    if !seen_nodes || !seen_elements {
        return Err(p.err(
            None,
            format!(
                "no {} section",
                if seen_nodes { "$Elements" } else { "$Nodes" }
            ),
            "`$Nodes` and `$Elements` sections",
        ));
    }
    let (mut mesh, index) = hex_mesh(&p, &nodes, &blocks)?;
    node_sets(&p, &mut mesh, &index, &nodes, &blocks, &names, &entity_phys)?;
    Ok(mesh)
}

/// The mesh of the hexahedra of `blocks`: the nodes they use, in increasing tag order
/// (`index`: node tag to mesh node), each element checked and turned to a positive volume.
fn hex_mesh(
    p: &Parser<'_>,
    nodes: &HashMap<u64, [f64; 3]>,
    blocks: &[Block],
) -> Result<(Mesh, HashMap<u64, usize>), IoError> {
    let mut used = BTreeSet::new();
    for b in blocks.iter().filter(|b| b.hex) {
        for (etag, line, v) in &b.elements {
            for &t in v {
                if !nodes.contains_key(&t) {
                    return Err(undefined_node(p, *etag, *line, t));
                }
                used.insert(t);
            }
        }
    }
    if used.is_empty() {
        return Err(p.err(
            None,
            "the file holds no hexahedron".into(),
            "8-node hexahedra (type 5); when physical groups are defined, Gmsh saves only \
             their elements: add a physical volume or set Mesh.SaveAll = 1",
        ));
    }
    let index: HashMap<u64, usize> = used.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    let mut mesh = Mesh {
        nodes: used.iter().map(|t| nodes[t]).collect(),
        ..Mesh::default()
    };
    for b in blocks.iter().filter(|b| b.hex) {
        for (etag, line, v) in &b.elements {
            let mut h = [0usize; 8];
            for (slot, t) in h.iter_mut().zip(v) {
                *slot = index[t];
            }
            let x = h.map(|n| mesh.nodes[n]);
            let vol = hex_volume(&x);
            let edge = squeal_fe::hex8::edge_lengths(&x)
                .into_iter()
                .fold(0.0, f64::max);
            if vol.is_nan() || vol.abs() <= 1e-12 * edge.powi(3) {
                return Err(p.err(
                    Some(*line),
                    format!("hexahedron {etag} is degenerate (volume {vol:e})"),
                    "hexahedra of non-zero volume",
                ));
            }
            if vol < 0.0 {
                h = [h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]];
            }
            // a repeated node (an edge of zero length) or an inverted corner leaves the
            // volume non-zero but the element unusable
            let q = squeal_fe::hex8::scaled_jacobian(&h.map(|n| mesh.nodes[n]));
            if q <= 0.0 {
                return Err(p.err(
                    Some(*line),
                    format!(
                        "hexahedron {etag} has a repeated node or an inverted corner \
                         (scaled Jacobian {q:.3})"
                    ),
                    "hexahedra whose eight corners are distinct and convex",
                ));
            }
            mesh.hexes.push(h);
        }
    }
    mesh.hex_body = vec![0; mesh.hexes.len()];
    Ok((mesh, index))
}

/// An element that references a node `$Nodes` does not define.
fn undefined_node(p: &Parser<'_>, etag: u64, line: usize, t: u64) -> IoError {
    p.err(
        Some(line),
        format!("element {etag} references node tag {t}, which $Nodes does not define"),
        "node tags defined in $Nodes",
    )
}

/// The physical groups of dimension 0 to 2 as node sets of `mesh` (named by
/// `$PhysicalNames`, else `physical_TAG`).
fn node_sets(
    p: &Parser<'_>,
    mesh: &mut Mesh,
    index: &HashMap<u64, usize>,
    nodes: &HashMap<u64, [f64; 3]>,
    blocks: &[Block],
    names: &HashMap<(usize, i64), String>,
    entity_phys: &HashMap<(usize, i64), Vec<i64>>,
) -> Result<(), IoError> {
    let mut groups: BTreeMap<(usize, i64), BTreeSet<usize>> = BTreeMap::new();
    for ((dim, _), phys) in entity_phys.iter().filter(|((d, _), _)| *d < 3) {
        for &ph in phys {
            groups.entry((*dim, ph)).or_default();
        }
    }
    for b in blocks.iter().filter(|b| b.dim < 3) {
        let Some(phys) = entity_phys.get(&(b.dim, b.tag)) else {
            continue;
        };
        for &ph in phys {
            let set = groups.entry((b.dim, ph)).or_default();
            for (etag, line, v) in &b.elements {
                for t in v {
                    if !nodes.contains_key(t) {
                        return Err(undefined_node(p, *etag, *line, *t));
                    }
                    if let Some(&i) = index.get(t) {
                        set.insert(i);
                    }
                }
            }
        }
    }
    for ((dim, ph), set) in groups {
        let name = names
            .get(&(dim, ph))
            .cloned()
            .unwrap_or_else(|| format!("physical_{ph}"));
        let entry = mesh.node_sets.entry(name).or_default();
        entry.extend(set);
        entry.sort_unstable();
        entry.dedup();
    }
    Ok(())
}

/// The sections of an MSH 4.1 file, each read by its own method.
impl Parser<'_> {
    /// `$MeshFormat`: version 4.1, ASCII.
    fn mesh_format(&mut self) -> Result<(), IoError> {
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
    fn physical_names(&mut self, names: &mut HashMap<(usize, i64), String>) -> Result<(), IoError> {
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
    fn entities(
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
    fn nodes(&mut self, nodes: &mut HashMap<u64, [f64; 3]>) -> Result<(), IoError> {
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
    fn elements(&mut self, blocks: &mut Vec<Block>) -> Result<(), IoError> {
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
    fn skip_section(&mut self, s: &str, line: usize) -> Result<(), IoError> {
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

/// Name of the physical volume [`write_msh`] puts every hexahedron in.
pub const VOLUME_GROUP: &str = "volume";

/// The six faces of a hexahedron, nodes ordered for an outward normal.
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// The MSH 4.1 ASCII text of `mesh`: every hexahedron in volume entity 1 (physical
/// volume [`VOLUME_GROUP`]), and for each
/// node set named in `groups` a surface entity and a physical surface of that name
/// holding the hexahedron faces whose four nodes all lie in the set. `file` names the
/// destination in errors: an unknown group, or a set that is not a union of faces.
pub fn msh_string(mesh: &Mesh, groups: &[&str], file: &Path) -> Result<String, IoError> {
    let err = |problem: String, expected: &str| IoError::Msh {
        file: file.to_path_buf(),
        line: None,
        problem,
        expected: expected.into(),
    };
    if mesh.hexes.is_empty() {
        return Err(err(
            "the mesh has no hexahedron".into(),
            "a hexahedral mesh",
        ));
    }
    for (n, p) in mesh.nodes.iter().enumerate() {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(err(format!("node {n} is at {p:?}"), "finite coordinates"));
        }
    }
    // faces of each group
    let mut faces: Vec<Vec<[usize; 4]>> = Vec::new();
    for &g in groups {
        let set = mesh
            .node_set(g)
            .map_err(|m| err(m, "node sets of the mesh"))?;
        let inside: HashSet<usize> = set.iter().copied().collect();
        let mut seen = HashSet::new();
        let mut fs = Vec::new();
        let mut covered = HashSet::new();
        for h in &mesh.hexes {
            for f in HEX_FACES {
                let q = f.map(|a| h[a]);
                if q.iter().all(|n| inside.contains(n)) {
                    let mut key = q;
                    key.sort_unstable();
                    if seen.insert(key) {
                        fs.push(q);
                        covered.extend(q);
                    }
                }
            }
        }
        if covered.len() != inside.len() {
            return Err(err(
                format!(
                    "node set `{g}` has {} nodes on no hexahedron face inside the set",
                    inside.len() - covered.len()
                ),
                "node sets that are unions of hexahedron faces",
            ));
        }
        faces.push(fs);
    }
    let bbox = |ns: &mut dyn Iterator<Item = usize>| {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for n in ns {
            for k in 0..3 {
                lo[k] = lo[k].min(mesh.nodes[n][k]);
                hi[k] = hi[k].max(mesh.nodes[n][k]);
            }
        }
        format!(
            "{:e} {:e} {:e} {:e} {:e} {:e}",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        )
    };
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat");
    // a physical volume too: Gmsh re-saves only physical elements, and meshio needs
    // every element block of a file with physical groups to have one
    let _ = writeln!(w, "$PhysicalNames\n{}", groups.len() + 1);
    for (i, g) in groups.iter().enumerate() {
        let _ = writeln!(w, "2 {} \"{g}\"", i + 1);
    }
    let _ = writeln!(w, "3 {} \"{VOLUME_GROUP}\"", groups.len() + 1);
    let _ = writeln!(w, "$EndPhysicalNames");
    let _ = writeln!(w, "$Entities\n0 0 {} 1", groups.len());
    for (i, fs) in faces.iter().enumerate() {
        let _ = writeln!(
            w,
            "{} {} 1 {} 0",
            i + 1,
            bbox(&mut fs.iter().flatten().copied()),
            i + 1
        );
    }
    let _ = writeln!(
        w,
        "1 {} 1 {} 0",
        bbox(&mut (0..mesh.nodes.len())),
        groups.len() + 1
    );
    let _ = writeln!(w, "$EndEntities");
    let n = mesh.nodes.len();
    let _ = writeln!(w, "$Nodes\n1 {n} 1 {n}\n3 1 0 {n}");
    for t in 1..=n {
        let _ = writeln!(w, "{t}");
    }
    for p in &mesh.nodes {
        let _ = writeln!(w, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    let _ = writeln!(w, "$EndNodes");
    let n_el = mesh.hexes.len() + faces.iter().map(Vec::len).sum::<usize>();
    let _ = writeln!(w, "$Elements\n{} {n_el} 1 {n_el}", groups.len() + 1);
    let mut tag = 0;
    for (i, fs) in faces.iter().enumerate() {
        let _ = writeln!(w, "2 {} 3 {}", i + 1, fs.len());
        for q in fs {
            tag += 1;
            let _ = writeln!(
                w,
                "{tag} {} {} {} {}",
                q[0] + 1,
                q[1] + 1,
                q[2] + 1,
                q[3] + 1
            );
        }
    }
    let _ = writeln!(w, "3 1 5 {}", mesh.hexes.len());
    for h in &mesh.hexes {
        tag += 1;
        let _ = write!(w, "{tag}");
        for &v in h {
            let _ = write!(w, " {}", v + 1);
        }
        let _ = writeln!(w);
    }
    let _ = writeln!(w, "$EndElements");
    Ok(s)
}

/// Writes `mesh` as a Gmsh MSH 4.1 ASCII file (see [`msh_string`]): nodes tagged 1..n in
/// mesh order, hexahedra in squeal's (= Gmsh's) node order, and one physical surface of
/// quadrangles per node set named in `groups`. Node sets not named are not written.
pub fn write_msh(mesh: &Mesh, path: &Path, groups: &[&str]) -> Result<(), IoError> {
    let text = msh_string(mesh, groups, path)?;
    std::fs::write(path, text).map_err(|source| IoError::Io {
        file: PathBuf::from(path),
        action: "write",
        source,
    })
}
