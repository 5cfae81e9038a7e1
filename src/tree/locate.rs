//! Point location: which leaf a point falls in.

use super::{NodeKind, VsTree};
use glam::Vec3;

impl VsTree {
    /// The deepest node whose cell contains `p`: descends octants in V-nodes and quadrants of
    /// the projection in T-/S-nodes. Stops early where the child that would contain `p` is
    /// empty (and so was never created). `None` when `p` is outside the root cube.
    pub fn locate(&self, p: Vec3) -> Option<usize> {
        let root = self.root();
        if ((p - root.center).abs() - root.half).max_element() > 0.0 {
            return None;
        }
        let mut i = 0;
        loop {
            let node = &self.nodes[i];
            if node.is_leaf() {
                return Some(i);
            }
            let slot = match node.kind {
                NodeKind::Volume => {
                    let c = node.center;
                    (p.x >= c.x) as u8 | ((p.y >= c.y) as u8) << 1 | ((p.z >= c.z) as u8) << 2
                }
                NodeKind::Transition | NodeKind::Surface => {
                    let f = &self.frames[node.frame as usize];
                    let c = if node.kind == NodeKind::Transition { f.square_center } else { node.center_uv() };
                    let q = f.project(p);
                    (q.x >= c.x) as u8 | ((q.y >= c.y) as u8) << 1
                }
            };
            match node.children().find(|&c| self.nodes[c].slot == slot) {
                Some(child) => i = child,
                None => return Some(i),
            }
        }
    }
}
