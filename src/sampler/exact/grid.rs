//! The accepted samples of an exact run, binned by square cells of `G` px
//! with `G` = ⌈r_max⌉ + 1: every sample whose disk can reach a point (or a
//! sub-pixel cell) of pixel p lies in a cell overlapping pixels p ± G.
//! Cells are linked lists, newest sample first, whose nodes hold the samples
//! themselves (one memory access per hop).

use super::Sample;
use crate::sampler::Plan;
use crate::sampler::cpu::cull::cells_along;
use crate::sampler::fixed::RADIUS_ONE;

const NONE: u32 = u32::MAX;

/// Accepted samples by cell.
pub struct SampleGrid {
    /// Cell side in pixels.
    g: u32,
    cols: u32,
    width: u32,
    height: u32,
    periodic: bool,
    head: Vec<u32>,
    nodes: Vec<Node>,
}

/// A sample and the next one of its cell.
#[derive(Clone, Copy)]
struct Node {
    sample: Sample,
    next: u32,
}

impl SampleGrid {
    /// An empty grid for `plan`.
    pub fn new(plan: &Plan) -> Self {
        let g = plan.radius_range.1.div_ceil(RADIUS_ONE) + 1;
        let (cols, rows) = (plan.width.div_ceil(g), plan.height.div_ceil(g));
        Self {
            g,
            cols,
            width: plan.width,
            height: plan.height,
            periodic: plan.periodic,
            head: vec![NONE; (cols * rows) as usize],
            nodes: Vec::new(),
        }
    }

    /// The cell of `s`'s pixel.
    fn cell_of(&self, s: &Sample) -> usize {
        let (px, py) = (s.pixel % self.width, s.pixel / self.width);
        ((py / self.g) * self.cols + px / self.g) as usize
    }

    /// Adds `s`, the next sample (indices are acceptance order).
    pub fn insert(&mut self, s: Sample) {
        let c = self.cell_of(&s);
        self.nodes.push(Node {
            sample: s,
            next: self.head[c],
        });
        self.head[c] = (self.nodes.len() - 1) as u32;
    }

    /// Takes sample `index` out of the grid. Its slot stays (indices are
    /// acceptance order), unlinked from its cell's list.
    pub fn remove(&mut self, index: u32) {
        let c = self.cell_of(&self.nodes[index as usize].sample);
        let after = self.nodes[index as usize].next;
        if self.head[c] == index {
            self.head[c] = after;
        } else {
            let mut i = self.head[c];
            while i != NONE {
                if self.nodes[i as usize].next == index {
                    self.nodes[i as usize].next = after;
                    break;
                }
                i = self.nodes[i as usize].next;
            }
        }
        self.nodes[index as usize].next = NONE;
    }

    /// Cell side in pixels.
    pub fn cell(&self) -> u32 {
        self.g
    }

    /// Cells per row.
    pub fn cols(&self) -> u32 {
        self.cols
    }

    /// The number of cells.
    pub fn cells(&self) -> usize {
        self.head.len()
    }

    /// Calls `f` with every cell index that may hold a sample reaching
    /// pixel (px, py).
    pub fn for_cells_near(&self, px: u32, py: u32, mut f: impl FnMut(usize)) {
        let (cols, nc) = cells_along(px, self.g, self.width, self.g, self.periodic);
        let (rows, nr) = cells_along(py, self.g, self.height, self.g, self.periodic);
        for &cy in &rows[..nr] {
            for &cx in &cols[..nc] {
                f((cy * self.cols + cx) as usize);
            }
        }
    }

    /// Calls `f` with every sample (and its index) of index at least `from`
    /// that may reach pixel (px, py), newest first within a cell, until `f`
    /// returns true; returns whether one did.
    pub fn any_near(
        &self,
        px: u32,
        py: u32,
        from: u32,
        mut f: impl FnMut(u32, &Sample) -> bool,
    ) -> bool {
        let (cols, nc) = cells_along(px, self.g, self.width, self.g, self.periodic);
        let (rows, nr) = cells_along(py, self.g, self.height, self.g, self.periodic);
        for &cy in &rows[..nr] {
            for &cx in &cols[..nc] {
                let mut i = self.head[(cy * self.cols + cx) as usize];
                while i != NONE && i >= from {
                    let node = &self.nodes[i as usize];
                    if f(i, &node.sample) {
                        return true;
                    }
                    i = node.next;
                }
            }
        }
        false
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * self.head.capacity() + std::mem::size_of::<Node>() * self.nodes.capacity()
    }
}
