//! The syntax tree the parser builds and the folder simplifies.
//!
//! Every operator and function call is an [`Node::Apply`] of an [`Op`] to its
//! arguments, so folding and code generation handle one shape. Each node records its
//! depth so the parser can refuse trees deep enough to overflow the stack of the
//! recursive passes that follow.

use super::ops::Op;

/// Deepest tree accepted (long operator chains like `1+1+...+1` are deep trees);
/// keeps the recursive passes (folding, code generation) well within a 2 MiB stack.
pub(crate) const MAX_DEPTH: u32 = 256;

/// Deepest parser recursion accepted: nested parentheses, calls, prefix operators and
/// `?:` branches. Each level costs about a dozen parser frames, so this is lower than
/// [`MAX_DEPTH`]; hand-written expressions rarely nest more than ten levels.
pub(crate) const MAX_NESTING: u32 = 100;

/// One node of the syntax tree.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Node {
    /// A literal or folded constant.
    Num(f64),
    /// Variable slot `i`.
    Var(u8),
    /// An operation applied to `op.arity()` arguments.
    Apply {
        /// The operation.
        op: Op,
        /// Its arguments, in order.
        args: Vec<Node>,
        /// `1 + max(argument depth)`.
        depth: u32,
    },
}

impl Node {
    /// Builds `op(args)`, recording the depth.
    pub(crate) fn apply(op: Op, args: Vec<Node>) -> Node {
        debug_assert_eq!(args.len(), op.arity(), "{op:?}");
        let depth = 1 + args.iter().map(Node::depth).max().unwrap_or(0);
        Node::Apply { op, args, depth }
    }

    /// Shorthand for a one-argument [`Node::apply`].
    pub(crate) fn unary(op: Op, a: Node) -> Node {
        Node::apply(op, vec![a])
    }

    /// Shorthand for a two-argument [`Node::apply`].
    #[cfg(test)]
    pub(crate) fn binary(op: Op, a: Node, b: Node) -> Node {
        Node::apply(op, vec![a, b])
    }

    /// Height of the tree: 1 for leaves.
    pub(crate) fn depth(&self) -> u32 {
        match self {
            Node::Num(_) | Node::Var(_) => 1,
            Node::Apply { depth, .. } => *depth,
        }
    }

    /// The constant value, if this is a [`Node::Num`].
    pub(crate) fn as_num(&self) -> Option<f64> {
        match self {
            Node::Num(v) => Some(*v),
            _ => None,
        }
    }

    /// Bit `i` set for every variable slot `i` the tree reads.
    pub(crate) fn used_vars(&self) -> u64 {
        match self {
            Node::Num(_) => 0,
            Node::Var(i) => 1u64 << i,
            Node::Apply { args, .. } => args.iter().fold(0, |m, a| m | a.used_vars()),
        }
    }
}
