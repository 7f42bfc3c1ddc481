//! Common-subexpression elimination: an ordered list of assignments for a set of roots.
//!
//! Every node reachable from the roots that is used more than once (by other reachable nodes
//! or as a root) becomes a temporary, computed once, in id order (children before parents).
//! `sin u` and `cos u` of one argument both present become one [`Temporary::SinCos`], which
//! the code generator emits as a single `sin_cos()` call. Everything else is inlined into its
//! single user. The order depends only on ids, never on hash-map iteration.

use super::{ExprArena, ExprId, Func, Node, node_operation_count};
use rustc_hash::FxHashMap;

/// One assignment of a [`CsePlan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Temporary {
    /// `let tN = <node>;`
    Single(ExprId),
    /// `let (tN_sin, tN_cos) = arg.sin_cos();` for the nodes `sin` = sin(arg), `cos` = cos(arg).
    SinCos {
        /// The shared argument.
        arg: ExprId,
        /// The node `sin(arg)`.
        sin: ExprId,
        /// The node `cos(arg)`.
        cos: ExprId,
    },
}

/// Evaluation plan for a set of roots: temporaries in order, then the roots.
#[derive(Debug, Clone)]
pub struct CsePlan {
    /// Assignments in evaluation order.
    pub temporaries: Vec<Temporary>,
    /// The root expressions, in the order given.
    pub roots: Vec<ExprId>,
    names: FxHashMap<ExprId, String>,
    operations: u64,
}

impl CsePlan {
    /// The temporary's variable name that holds `id`, if `id` is a temporary.
    pub fn name_of(&self, id: ExprId) -> Option<&str> {
        self.names.get(&id).map(String::as_str)
    }

    /// Arithmetic operations the plan performs (each reachable operation once; a `sin_cos`
    /// pair counts one).
    pub fn operation_count(&self) -> u64 {
        self.operations
    }

    /// Variable names of a temporary: one for [`Temporary::Single`], `(sin, cos)` for a pair.
    pub fn temporary_names(&self, temp: &Temporary) -> (String, Option<String>) {
        match *temp {
            Temporary::Single(e) => (self.names[&e].clone(), None),
            Temporary::SinCos { sin, cos, .. } => {
                (self.names[&sin].clone(), Some(self.names[&cos].clone()))
            }
        }
    }
}

/// The operations [`plan`] would count for `roots` ([`CsePlan::operation_count`]), without
/// building the plan: for choosing between candidate forms of an expression, where only the
/// cost matters.
pub fn operation_count(arena: &ExprArena, roots: &[ExprId]) -> u64 {
    let reachable = arena.reachable(roots);
    let mut operations = 0u64;
    let mut cosines: rustc_hash::FxHashSet<ExprId> = Default::default();
    for &e in &reachable {
        let node = arena.node(e);
        operations += node_operation_count(node);
        if let Node::Func(Func::Cos, u) = node {
            cosines.insert(*u);
        }
    }
    // One `sin_cos` call computes a sine and a cosine of the same argument.
    let pairs = reachable
        .iter()
        .filter(|&&e| matches!(arena.node(e), Node::Func(Func::Sin, u) if cosines.contains(u)))
        .count() as u64;
    operations - pairs
}

/// Plans the evaluation of `roots`; temporaries are named `{prefix}{k}` (`{prefix}{k}_s` and
/// `{prefix}{k}_c` for a sine–cosine pair).
pub fn plan(arena: &ExprArena, roots: &[ExprId], prefix: &str) -> CsePlan {
    let reachable = arena.reachable(roots);
    let mut uses: FxHashMap<ExprId, u32> = FxHashMap::default();
    for &e in &reachable {
        for &c in arena.node(e).children() {
            *uses.entry(c).or_default() += 1;
        }
    }
    for &r in roots {
        *uses.entry(r).or_default() += 1;
    }
    let index: FxHashMap<ExprId, usize> =
        reachable.iter().enumerate().map(|(i, e)| (*e, i)).collect();

    // Pair sin(u) with cos(u) when both are needed.
    let mut partner: FxHashMap<ExprId, ExprId> = FxHashMap::default();
    let mut cos_of: FxHashMap<ExprId, ExprId> = FxHashMap::default();
    for &e in &reachable {
        if let Node::Func(Func::Cos, u) = arena.node(e) {
            cos_of.insert(*u, e);
        }
    }
    for &e in &reachable {
        if let Node::Func(Func::Sin, u) = arena.node(e)
            && let Some(&c) = cos_of.get(u)
        {
            partner.insert(e, c);
            partner.insert(c, e);
        }
    }

    let mut temporaries = Vec::new();
    let mut names = FxHashMap::default();
    let mut operations = 0u64;
    for &e in &reachable {
        let node = arena.node(e);
        operations += node_operation_count(node);
        if matches!(node, Node::Const(_) | Node::Pi | Node::Symbol(_)) {
            continue;
        }
        if let Some(&p) = partner.get(&e) {
            if p < e {
                // Emitted with its partner; one call computes both.
                operations -= 1;
                continue;
            }
            let (sin, cos) = match node {
                Node::Func(Func::Sin, _) => (e, p),
                _ => (p, e),
            };
            let Node::Func(_, arg) = *node else { continue };
            let k = temporaries.len();
            names.insert(sin, format!("{prefix}{k}_s"));
            names.insert(cos, format!("{prefix}{k}_c"));
            temporaries.push(Temporary::SinCos { arg, sin, cos });
            continue;
        }
        if uses.get(&e).copied().unwrap_or(0) >= 2 {
            let k = temporaries.len();
            names.insert(e, format!("{prefix}{k}"));
            temporaries.push(Temporary::Single(e));
        }
    }
    debug_assert!(temporaries.windows(2).all(|w| {
        let first = |t: &Temporary| match *t {
            Temporary::Single(e) => index[&e],
            Temporary::SinCos { sin, cos, .. } => index[&sin].min(index[&cos]),
        };
        first(&w[0]) < first(&w[1])
    }));
    CsePlan {
        temporaries,
        roots: roots.to_vec(),
        names,
        operations,
    }
}
