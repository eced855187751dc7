//! DOF numbering: reverse Cuthill-McKee on the node graph, three DOFs per node
//! interleaved, Dirichlet conditions and node ties by elimination.
//!
//! RCM (Cuthill & McKee 1969, George 1971) gives a small profile, so fill stays low for
//! any factorization; the factorizations further reorder for fill
//! (`squeal_core::ordering`). Eliminated DOFs are
//! simply not numbered: the assembled matrices live on the free DOFs only.
//!
//! A [`Tie`] makes a node move as a weighted sum of other nodes (a hanging node of a fine
//! mesh on a coarse element face, weights the coarse face's shape functions there). Its
//! DOFs are eliminated too (master-slave elimination, `u = T q`): the assembly scatters
//! its element entries onto the masters' DOFs, so the matrices are `T^T K T`.

use crate::mesh::Mesh;
use std::collections::VecDeque;

/// A node tied to others: `u(slave) = sum_k w_k u(master_k)`, each component alike.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The tied (hanging) node.
    pub slave: usize,
    /// Master nodes and weights (the weights of an interpolation sum to 1).
    pub masters: Vec<(usize, f64)>,
}

/// Sorted node adjacency lists (nodes sharing an element), self excluded.
pub fn node_graph(mesh: &Mesh) -> Vec<Vec<usize>> {
    tied_node_graph(mesh, &[])
}

/// [`node_graph`] after the ties' elimination: a tied node is replaced by its masters in
/// every element (so they become neighbours of the element's other nodes) and has no
/// neighbour itself.
pub fn tied_node_graph(mesh: &Mesh, ties: &[Tie]) -> Vec<Vec<usize>> {
    let mut sub: Vec<Option<&[(usize, f64)]>> = vec![None; mesh.n_nodes()];
    for t in ties {
        sub[t.slave] = Some(&t.masters);
    }
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); mesh.n_nodes()];
    let mut eff: Vec<usize> = Vec::with_capacity(32);
    for h in &mesh.hexes {
        eff.clear();
        for &a in h {
            match sub[a] {
                Some(ms) => eff.extend(ms.iter().map(|m| m.0)),
                None => eff.push(a),
            }
        }
        for &a in &eff {
            for &b in &eff {
                if a != b {
                    adj[a].push(b);
                }
            }
        }
    }
    for l in adj.iter_mut() {
        l.sort_unstable();
        l.dedup();
    }
    adj
}

/// Reverse Cuthill-McKee order of the nodes: `order[k]` is the node numbered `k`.
/// Each connected component starts from a pseudo-peripheral node (George-Liu).
pub fn rcm_order(adj: &[Vec<usize>]) -> Vec<usize> {
    let n = adj.len();
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    let bfs_levels = |start: usize| -> (Vec<usize>, usize) {
        let mut lvl = vec![usize::MAX; n];
        let mut q = VecDeque::from([start]);
        lvl[start] = 0;
        let mut last = start;
        while let Some(a) = q.pop_front() {
            last = a;
            for &b in &adj[a] {
                if lvl[b] == usize::MAX {
                    lvl[b] = lvl[a] + 1;
                    q.push_back(b);
                }
            }
        }
        let depth = lvl[last];
        (lvl, depth)
    };
    for root in 0..n {
        if seen[root] {
            continue;
        }
        // pseudo-peripheral node: repeat BFS from a min-degree node of the last level
        let mut start = root;
        let (mut lvl, mut depth) = bfs_levels(start);
        for _ in 0..8 {
            let cand = (0..n)
                .filter(|&i| lvl[i] == depth)
                .min_by_key(|&i| adj[i].len())
                .unwrap_or(start);
            let (l2, d2) = bfs_levels(cand);
            if d2 <= depth {
                break;
            }
            start = cand;
            lvl = l2;
            depth = d2;
        }
        let begin = order.len();
        let mut q = VecDeque::from([start]);
        seen[start] = true;
        while let Some(a) = q.pop_front() {
            order.push(a);
            let mut next: Vec<usize> = adj[a].iter().copied().filter(|&b| !seen[b]).collect();
            next.sort_by_key(|&b| adj[b].len());
            for b in next {
                seen[b] = true;
                q.push_back(b);
            }
        }
        order[begin..].reverse();
    }
    order
}

/// Maximum `|new(a) - new(b)|` over adjacent nodes for a node numbering `rank`.
pub fn bandwidth(adj: &[Vec<usize>], rank: &[usize]) -> usize {
    adj.iter()
        .enumerate()
        .flat_map(|(a, l)| l.iter().map(move |&b| (a, b)))
        .map(|(a, b)| rank[a].abs_diff(rank[b]))
        .max()
        .unwrap_or(0)
}

/// Map from full DOFs (`3 node + component`) to free (numbered) DOFs.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    /// Free index of each full DOF, `None` where eliminated.
    pub free_of_full: Vec<Option<usize>>,
    /// Full DOF of each free index.
    pub full_of_free: Vec<usize>,
    /// Tied full DOFs (their `free_of_full` is `None`) and the free DOFs and weights they
    /// follow, sorted by full DOF. Empty without ties.
    pub tied: Vec<(usize, Vec<(usize, f64)>)>,
}

impl DofMap {
    /// Numbers the DOFs of `mesh` in RCM node order, three per node, skipping the
    /// `fixed` full DOFs (Dirichlet by elimination). Nodes used by no element get no DOF.
    pub fn new(mesh: &Mesh, fixed: &[usize]) -> DofMap {
        Self::with_ties(mesh, fixed, &[]).expect("no ties, nothing to check")
    }

    /// [`DofMap::new`] with the tied nodes `ties` eliminated as well. A tied component
    /// that is also fixed stays fixed; fixed masters contribute nothing. A node tied
    /// twice, a master that is itself tied, a weight that is not finite or a node out of
    /// range is an error message.
    pub fn with_ties(mesh: &Mesh, fixed: &[usize], ties: &[Tie]) -> Result<DofMap, String> {
        let nn = mesh.n_nodes();
        let mut is_slave = vec![false; nn];
        for t in ties {
            if t.slave >= nn || t.masters.iter().any(|m| m.0 >= nn) {
                return Err(format!(
                    "tie of node {} names a node beyond the mesh's {nn}",
                    t.slave
                ));
            }
            if std::mem::replace(&mut is_slave[t.slave], true) {
                return Err(format!("node {} is tied twice", t.slave));
            }
            if t.masters.is_empty() || t.masters.iter().any(|m| !m.1.is_finite()) {
                return Err(format!(
                    "tie of node {}: expected masters with finite weights, got {:?}",
                    t.slave, t.masters
                ));
            }
        }
        if let Some(t) = ties
            .iter()
            .find(|t| t.masters.iter().any(|m| is_slave[m.0]))
        {
            return Err(format!(
                "node {} is tied to a node that is tied itself (chains are not supported)",
                t.slave
            ));
        }
        let adj = tied_node_graph(mesh, ties);
        let order = rcm_order(&adj);
        let n_full = 3 * mesh.n_nodes();
        let mut is_fixed = vec![false; n_full];
        for &d in fixed {
            is_fixed[d] = true;
        }
        let mut free_of_full = vec![None; n_full];
        let mut full_of_free = Vec::new();
        for node in order {
            if adj[node].is_empty() {
                continue;
            }
            for c in 0..3 {
                let d = 3 * node + c;
                if !is_fixed[d] {
                    free_of_full[d] = Some(full_of_free.len());
                    full_of_free.push(d);
                }
            }
        }
        let mut tied = Vec::new();
        for t in ties {
            for c in 0..3 {
                let d = 3 * t.slave + c;
                if is_fixed[d] {
                    continue;
                }
                let to: Vec<(usize, f64)> = t
                    .masters
                    .iter()
                    .filter_map(|&(m, w)| free_of_full[3 * m + c].map(|f| (f, w)))
                    .collect();
                tied.push((d, to));
            }
        }
        tied.sort_by_key(|t| t.0);
        Ok(DofMap {
            free_of_full,
            full_of_free,
            tied,
        })
    }

    /// The node-level ties behind [`DofMap::tied`] (masters that have a free DOF; the
    /// weights of the first tied component), for graphs and patterns.
    pub fn node_ties(&self) -> Vec<Tie> {
        let mut out: Vec<Tie> = Vec::new();
        for (d, to) in &self.tied {
            let slave = d / 3;
            let masters = to.iter().map(|&(f, w)| (self.full_of_free[f] / 3, w));
            match out.last_mut() {
                Some(t) if t.slave == slave => {
                    for (m, w) in masters {
                        if !t.masters.iter().any(|x| x.0 == m) {
                            t.masters.push((m, w));
                        }
                    }
                }
                _ => out.push(Tie {
                    slave,
                    masters: masters.collect(),
                }),
            }
        }
        out
    }

    /// The free DOFs and weights full DOF `d` follows: itself, its masters' (tied), or
    /// none (fixed). `buf` is cleared and filled.
    pub fn follows(&self, d: usize, buf: &mut Vec<(usize, f64)>) {
        buf.clear();
        match self.free_of_full[d] {
            Some(f) => buf.push((f, 1.0)),
            None => {
                if let Ok(k) = self.tied.binary_search_by_key(&d, |t| t.0) {
                    buf.extend_from_slice(&self.tied[k].1);
                }
            }
        }
    }

    /// All three DOFs of each node in `nodes`, for [`DofMap::new`]'s `fixed`.
    pub fn node_dofs(nodes: &[usize]) -> Vec<usize> {
        nodes
            .iter()
            .flat_map(|&n| [3 * n, 3 * n + 1, 3 * n + 2])
            .collect()
    }

    /// Number of free DOFs.
    pub fn n_free(&self) -> usize {
        self.full_of_free.len()
    }

    /// Scatters a free-DOF vector to full DOFs: fixed DOFs get 0, tied DOFs their
    /// masters' weighted sum.
    pub fn expand(&self, free: &[f64]) -> Vec<f64> {
        let mut full = vec![0.0; self.free_of_full.len()];
        for (i, &d) in self.full_of_free.iter().enumerate() {
            full[d] = free[i];
        }
        for (d, to) in &self.tied {
            full[*d] = to.iter().map(|&(f, w)| w * free[f]).sum();
        }
        full
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::linspace;

    #[test]
    fn rcm_is_a_permutation_and_narrows_the_band() {
        // a long thin block numbered along its long axis last: natural order is wide
        let m = Mesh::block(
            &linspace(0.0, 1.0, 3),
            &linspace(0.0, 1.0, 3),
            &linspace(0.0, 10.0, 40),
        );
        let mut m2 = m.clone();
        // scramble node numbering to make the natural band large
        let n = m.n_nodes();
        let perm: Vec<usize> = (0..n).map(|i| (i * 7919) % n).collect();
        let mut inv = vec![0; n];
        for (i, &p) in perm.iter().enumerate() {
            inv[p] = i;
        }
        m2.nodes = (0..n).map(|k| m.nodes[perm[k]]).collect();
        m2.hexes = m.hexes.iter().map(|h| h.map(|a| inv[a])).collect();
        let adj = node_graph(&m2);
        let order = rcm_order(&adj);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        let mut rank = vec![0; n];
        for (k, &a) in order.iter().enumerate() {
            rank[a] = k;
        }
        let natural: Vec<usize> = (0..n).collect();
        let b_rcm = bandwidth(&adj, &rank);
        let b_nat = bandwidth(&adj, &natural);
        // 16 nodes per layer: a level structure spans about two layers
        assert!(b_rcm <= 2 * 16 + 8, "rcm bandwidth {b_rcm}");
        assert!(b_nat > 5 * b_rcm, "natural {b_nat} vs rcm {b_rcm}");
    }

    #[test]
    fn dirichlet_dofs_are_not_numbered() {
        let m = Mesh::block(
            &linspace(0.0, 1.0, 1),
            &linspace(0.0, 1.0, 1),
            &linspace(0.0, 1.0, 1),
        );
        let fixed = DofMap::node_dofs(m.node_set("zmin").unwrap());
        let d = DofMap::new(&m, &fixed);
        assert_eq!(d.n_free(), 12);
        for &f in &fixed {
            assert!(d.free_of_full[f].is_none());
        }
        let full = d.expand(&[1.0; 12]);
        assert_eq!(full.iter().sum::<f64>(), 12.0);
    }
}
