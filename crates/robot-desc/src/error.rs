//! The error type of this crate.

use lane_math::{Classify, ErrorClass};

/// Why a robot description was refused or could not be exported. Every message is one line
/// naming the element (`joint 'elbow'`, `link 'tool'`, `<inertial>` of a link) and the problem.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DescError {
    /// The text is longer than [`MAX_URDF_BYTES`](crate::MAX_URDF_BYTES).
    #[error("a robot description may have at most {max} bytes, got {got}")]
    TooLarge {
        /// The text's length (bytes).
        got: usize,
        /// The limit.
        max: usize,
    },
    /// The text is not well-formed XML, or uses a DTD (refused: no entity is ever expanded).
    #[error("not a readable XML document: {0}")]
    Xml(roxmltree::Error),
    /// More XML nodes than [`MAX_XML_NODES`](crate::MAX_XML_NODES).
    #[error("more than the {max} XML nodes a robot description may have")]
    TooManyNodes {
        /// The limit.
        max: u32,
    },
    /// Elements nest deeper than [`MAX_XML_DEPTH`](crate::MAX_XML_DEPTH).
    #[error("elements nest deeper than {max} levels (at line {line}); URDF needs 5")]
    TooDeep {
        /// The limit.
        max: usize,
        /// The line of the first element past it.
        line: u32,
    },
    /// An attribute value is longer than [`MAX_ATTRIBUTE_BYTES`](crate::MAX_ATTRIBUTE_BYTES).
    #[error(
        "attribute {attribute:?} of <{element}> (line {line}) has {got} bytes, at most {max} allowed"
    )]
    AttributeTooLong {
        /// The element's tag name.
        element: String,
        /// The attribute's name.
        attribute: String,
        /// Its line.
        line: u32,
        /// Its length (bytes).
        got: usize,
        /// The limit.
        max: usize,
    },
    /// An element has more than [`MAX_ATTRIBUTES`](crate::MAX_ATTRIBUTES) attributes.
    #[error("an element at line {line} has more than {max} attributes; URDF needs 6")]
    TooManyAttributes {
        /// The element's line.
        line: u32,
        /// The limit.
        max: usize,
    },
    /// The text declares more than [`MAX_NAMESPACES`](crate::MAX_NAMESPACES) XML namespaces.
    #[error("the text has {got} namespace declarations (xmlns), at most {max} allowed")]
    TooManyNamespaces {
        /// The declarations counted (every `xmlns` in the text).
        got: usize,
        /// The limit.
        max: usize,
    },
    /// An element is malformed or outside the model's domain (a NaN mass, a zero axis, an
    /// inertia breaking the triangle inequality, a missing attribute, a duplicated name).
    #[error("{element}: {problem}")]
    Invalid {
        /// The element, e.g. `joint 'elbow'` or `<inertial> of link 'upper'`.
        element: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The description is valid URDF but not a serial chain this crate models (a tree, a closed
    /// loop, a floating or planar joint, a link without a path to the root).
    #[error(
        "{element}: {problem} (only serial chains of revolute, continuous, prismatic and fixed joints are read)"
    )]
    NotAChain {
        /// The element.
        element: String,
        /// What makes it not a serial chain.
        problem: String,
    },
    /// The model cannot be written in the asked format (a massless link at the end of a chain
    /// for MuJoCo, a chain deeper than MuJoCo compiles).
    #[error("cannot export {element}: {problem}")]
    Export {
        /// The element that cannot be written.
        element: String,
        /// Why.
        problem: String,
    },
}

impl Classify for DescError {
    /// Always [`InvalidInput`](ErrorClass::InvalidInput): a description is read, checked and
    /// written, never computed with.
    fn class(&self) -> ErrorClass {
        ErrorClass::InvalidInput
    }
}

impl DescError {
    /// An [`DescError::Invalid`] error.
    pub(crate) fn invalid(element: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::Invalid {
            element: element.into(),
            problem: problem.into(),
        }
    }

    /// A [`DescError::NotAChain`] error.
    pub(crate) fn not_a_chain(element: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::NotAChain {
            element: element.into(),
            problem: problem.into(),
        }
    }

    /// A [`DescError::Export`] error.
    pub(crate) fn export(element: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::Export {
            element: element.into(),
            problem: problem.into(),
        }
    }
}
