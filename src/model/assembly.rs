//! The product structure of a model: a tree of named, placed nodes, and the
//! part instances at its nodes, each a placed copy of a shape.
//!
//! A reader that knows the structure (STEP) builds it; for any other model
//! [`Assembly::single`] is one node with one instance of one shape. Meshing
//! by instances ([`crate::mesh_instanced`]) meshes each shape once.

use alloc::string::String;
use alloc::vec::Vec;
use glam::DAffine3;

/// One node of the tree: an assembly, a sub-assembly or a part occurrence.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AssemblyNode {
    /// The product's name ("" when the file gives none).
    pub name: String,
    /// The occurrence's own name where the file gives one (a STEP
    /// `NEXT_ASSEMBLY_USAGE_OCCURRENCE`'s, e.g. `nut_1`).
    pub occurrence: Option<String>,
    /// From this node's coordinates to its parent's (the identity at the
    /// root), in the model's length unit.
    pub matrix: DAffine3,
    /// Child nodes: indices into [`Assembly::nodes`].
    pub children: Vec<usize>,
    /// The part instances placed at this node: indices into [`Assembly::instances`].
    pub instances: Vec<usize>,
}

impl AssemblyNode {
    /// A node named `name`, at the identity, without children or instances.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            occurrence: None,
            matrix: DAffine3::IDENTITY,
            children: Vec::new(),
            instances: Vec::new(),
        }
    }
}

/// One placed copy of a shape: a set of the model's faces.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PartInstance {
    /// Its node in [`Assembly::nodes`].
    pub node: usize,
    /// Instances with the same shape are the same faces up to their
    /// matrices (the reader placed one item of the file at both).
    pub shape: usize,
    /// From the node's coordinates to the model's: the product of the
    /// matrices from the root down to the node. The model's faces of this
    /// instance are the shape's faces under it.
    pub matrix: DAffine3,
}

/// The tree and the part instances of a model.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Assembly {
    /// Every node; `nodes[0]` is the root.
    pub nodes: Vec<AssemblyNode>,
    /// One per part instance, numbered as [`crate::StepModel::parts`].
    pub instances: Vec<PartInstance>,
    /// For each face of the model ([`crate::Model::faces`], then
    /// [`crate::Model::tessellated`]), its instance.
    pub face_instances: Vec<u32>,
}

impl Assembly {
    /// A model without structure: a root named `name` holding one instance
    /// of one shape, every one of `faces` faces.
    pub fn single(name: impl Into<String>, faces: usize) -> Self {
        let mut root = AssemblyNode::new(name);
        root.instances.push(0);
        Self {
            nodes: alloc::vec![root],
            instances: alloc::vec![PartInstance { node: 0, shape: 0, matrix: DAffine3::IDENTITY }],
            face_instances: alloc::vec![0; faces],
        }
    }
}
