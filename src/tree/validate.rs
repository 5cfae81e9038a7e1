//! The tree's invariants, checked: tests call this on every model.

use super::{NodeKind, VsTree, NO_FRAME};

impl VsTree {
    /// Checks every structural invariant and returns the first violation found:
    /// every sample in exactly one leaf; children's ranges tile their parent's; children's
    /// cells inside their parent's; samples inside their node's cell; V-nodes have V/T
    /// children, T- and S-nodes have S children (so T-nodes sit exactly at the 3D/2D
    /// boundary); frames orthonormal; `index` a permutation of the input samples.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.samples.len();
        if self.nodes.is_empty() {
            return Err("no nodes".into());
        }
        let root = &self.nodes[0];
        if root.start != 0 || root.count as usize != n || root.kind == NodeKind::Surface {
            return Err(format!("root covers {}..+{} of {n} samples, kind {:?}", root.start, root.count, root.kind));
        }
        let mut seen = vec![false; n];
        for s in &self.samples {
            let i = s.index as usize;
            if i >= n || std::mem::replace(&mut seen[i], true) {
                return Err(format!("sample index {i} out of range or repeated"));
            }
        }
        // Frames first: the nodes' checks project samples with them.
        for (i, f) in self.frames.iter().enumerate() {
            let ok = [f.normal, f.u, f.v].iter().all(|a| (a.length() - 1.0).abs() < 1e-4)
                && f.normal.dot(f.u).abs() < 1e-4
                && f.normal.dot(f.v).abs() < 1e-4
                && f.u.dot(f.v).abs() < 1e-4
                && f.square_half > 0.0;
            if !ok {
                return Err(format!("frame {i} is not orthonormal: {f:?}"));
            }
        }
        let mut covered = vec![0u8; n];
        for (i, node) in self.nodes.iter().enumerate() {
            self.check_node(i).map_err(|e| format!("node {i} ({:?}, depth {}): {e}", node.kind, node.depth))?;
            if node.is_leaf() {
                for c in &mut covered[node.range()] {
                    *c += 1;
                }
            }
        }
        if let Some(i) = covered.iter().position(|&c| c != 1) {
            return Err(format!("sample {i} is in {} leaves", covered[i]));
        }
        Ok(())
    }

    fn check_node(&self, i: usize) -> Result<(), String> {
        let node = &self.nodes[i];
        if node.count == 0 || node.range().end > self.samples.len() {
            return Err(format!("bad range {}..+{}", node.start, node.count));
        }
        let has_frame = node.frame != NO_FRAME && (node.frame as usize) < self.frames.len();
        if (node.kind == NodeKind::Volume) == has_frame {
            return Err(format!("frame {} does not fit the node kind", node.frame));
        }
        // Samples inside the cell (with a tolerance for float rounding).
        let tol = 1e-4 * node.half.max(1e-12) + 1e-6 * self.diagonal;
        let outside = match node.kind {
            NodeKind::Volume | NodeKind::Transition => self
                .samples_of(node)
                .iter()
                .position(|s| ((s.position - node.center).abs() - node.half).max_element() > tol),
            NodeKind::Surface => {
                let f = &self.frames[node.frame as usize];
                self.samples_of(node)
                    .iter()
                    .position(|s| ((f.project(s.position) - node.center_uv()).abs() - node.half).max_element() > tol)
            }
        };
        if let Some(k) = outside {
            return Err(format!("sample {} lies outside the cell", node.start as usize + k));
        }
        if node.kind == NodeKind::Transition {
            let f = &self.frames[node.frame as usize];
            let outside = self
                .samples_of(node)
                .iter()
                .any(|s| ((f.project(s.position) - f.square_center).abs() - f.square_half).max_element() > tol);
            if outside {
                return Err("a sample projects outside the T-node's square".into());
            }
        }
        if node.is_leaf() {
            return Ok(());
        }
        let children = node.children();
        if children.end > self.nodes.len() || children.start <= i {
            return Err(format!("bad children {children:?}"));
        }
        let mut next = node.start;
        for c in children {
            let child = &self.nodes[c];
            if child.parent as usize != i || child.start != next || child.depth != node.depth + 1 {
                return Err(format!(
                    "child {c} has parent {}, start {}, depth {}",
                    child.parent, child.start, child.depth
                ));
            }
            next += child.count;
            let kind_ok = match node.kind {
                NodeKind::Volume => child.kind != NodeKind::Surface,
                NodeKind::Transition | NodeKind::Surface => {
                    child.kind == NodeKind::Surface && child.frame == node.frame
                }
            };
            if !kind_ok {
                return Err(format!("a {:?} node has a {:?} child", node.kind, child.kind));
            }
            let half_ok = (child.half - 0.5 * node.half).abs() <= 1e-5 * node.half || node.kind == NodeKind::Transition;
            let inside = match (node.kind, child.kind) {
                (NodeKind::Volume, _) => {
                    ((child.center - node.center).abs() + child.half - node.half).max_element() <= tol
                }
                (NodeKind::Transition, _) => {
                    let f = &self.frames[node.frame as usize];
                    ((child.center_uv() - f.square_center).abs() + child.half - f.square_half).max_element() <= tol
                }
                _ => ((child.center_uv() - node.center_uv()).abs() + child.half - node.half).max_element() <= tol,
            };
            if !half_ok || !inside {
                return Err(format!("child {c}'s cell is not a sub-cell of its parent's"));
            }
        }
        if next != node.start + node.count {
            return Err("children's ranges do not cover the node's".into());
        }
        Ok(())
    }
}
