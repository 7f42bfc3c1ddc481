//! Hash-consed expression DAG with canonical construction.
//!
//! Every expression lives in an [`ExprArena`] as a [`Node`] whose children are [`ExprId`]s
//! created before it (children precede parents, as in egg). Structurally equal nodes get the
//! same id. Constructors canonicalise:
//!
//! - sums and products are flattened and their operands sorted by id, so `x + y` and `y + x`
//!   are one node;
//! - constants are folded (exactly, for rationals), `x·1`, `x + 0`, `x^1`, `x^0`, `0·x` fold;
//! - like terms are collected (`2x + 3x = 5x`), like factors too (`x·x^2 = x^3`);
//! - integer powers distribute over products (`(2x)^2 = 4x^2`) and nest (`(x^2)^3 = x^6`);
//! - `c·X·sin²u + c·X·cos²u` collapses to `c·X` (the Pythagorean identity, which every
//!   `½ m v·v` of a rotating point produces);
//! - `sin`, `tan`, … are odd and `cos`, `cosh` even in a negated argument
//!   (`cos(-θ) = cos θ`), so `sin θ` and `cos θ` of one angle are each one node and the code
//!   generator can compute them with one `sin_cos`.
//!
//! Besides canonical construction, [`ExprArena::expand`] (and
//! [`ExprArena::expand_time_varying`]) multiply out, and
//! [`ExprArena::collect_time_varying`] groups a multiplied-out sum by its time-varying factors
//! and pulls common factors out (the compact form of the equations of a chain).
//!
//! The arena keeps, per node, what the derivations ask about it most often: which symbols it
//! may contain (so most `∂e/∂x` are known to be zero without a walk), whether it changes in
//! time, and its operation count as a tree. Hash-cons lookups take a borrowed node, so finding
//! an existing node allocates nothing.
//!
//! Nothing here iterates a `HashMap`: every output order is id order or insertion order, so
//! the same construction sequence gives byte-identical results.

mod collect;
mod constant;
pub mod cse;
mod diff;
pub mod eval;
mod expand;
pub mod print;
mod simplify;
pub mod trig;

pub use constant::{Constant, FoldError, fold};

use rustc_hash::FxHashMap;

mod products;
mod sums;

/// Index of a node in an [`ExprArena`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ExprId(pub u32);

impl ExprId {
    /// The index into the arena's node list.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Index of a symbol in an [`ExprArena`]'s symbol table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SymbolId(pub u32);

impl SymbolId {
    /// The index into the symbol table.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Elementary functions of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    /// sine
    Sin,
    /// cosine
    Cos,
    /// tangent
    Tan,
    /// arcsine
    Asin,
    /// arccosine
    Acos,
    /// arctangent
    Atan,
    /// hyperbolic sine
    Sinh,
    /// hyperbolic cosine
    Cosh,
    /// hyperbolic tangent
    Tanh,
    /// exponential
    Exp,
    /// natural logarithm
    Ln,
    /// absolute value
    Abs,
    /// sign (−1, 0, 1)
    Sign,
    /// Heaviside step: 0 for `x < 0`, 1 for `x ≥ 0` (HW9's `H(t)`)
    Step,
}

impl Func {
    /// The name used in model files and text output.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Abs => "abs",
            Func::Sign => "sign",
            Func::Step => "step",
        }
    }

    /// The function named `name` in a model file (`sqrt` and `atan2` are not here: they are
    /// a power and a two-argument node).
    pub fn from_name(name: &str) -> Option<Func> {
        Some(match name {
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "asin" => Func::Asin,
            "acos" => Func::Acos,
            "atan" => Func::Atan,
            "sinh" => Func::Sinh,
            "cosh" => Func::Cosh,
            "tanh" => Func::Tanh,
            "exp" => Func::Exp,
            "ln" => Func::Ln,
            "abs" => Func::Abs,
            "sign" => Func::Sign,
            "step" => Func::Step,
            _ => return None,
        })
    }

    /// Evaluates the function at `x`.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Abs => x.abs(),
            Func::Sign => {
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
            Func::Step => {
                if x >= 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    }

    /// `f(x)` of a number `x` by the one rule of folding ([`fold`]): an exact 0 is where the
    /// function vanishes (at 0; `ln` and `acos` at 1; `abs`, `sign`, `step`, which are exact,
    /// anywhere), so `exp(-1000)`, 0 in `f64`, is an underflow.
    ///
    /// # Errors
    /// As [`fold`]: `ln(-1)` is undefined, `cosh(1000)` overflows, `exp(-1000)` underflows.
    pub fn fold(self, x: f64) -> Result<f64, FoldError> {
        let exact_zero = x == 0.0
            || matches!(self, Func::Abs | Func::Sign | Func::Step)
            || x == 1.0 && matches!(self, Func::Ln | Func::Acos);
        fold(self.apply(x), exact_zero)
    }

    /// `f(-x) = -f(x)`.
    fn is_odd(self) -> bool {
        matches!(
            self,
            Func::Sin | Func::Tan | Func::Asin | Func::Atan | Func::Sinh | Func::Tanh | Func::Sign
        )
    }

    /// `f(-x) = f(x)`.
    fn is_even(self) -> bool {
        matches!(self, Func::Cos | Func::Cosh | Func::Abs)
    }
}

/// One operation of the DAG.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Node {
    /// A number.
    Const(Constant),
    /// π.
    Pi,
    /// A symbol: parameter, coordinate, rate, acceleration or time.
    Symbol(SymbolId),
    /// Sum of at least two terms, canonical (see the module docs).
    Add(Box<[ExprId]>),
    /// Product of at least two factors; a constant coefficient, if any, comes first.
    Mul(Box<[ExprId]>),
    /// `base ^ exponent`.
    Pow([ExprId; 2]),
    /// A function of one argument.
    Func(Func, ExprId),
    /// `atan2(y, x)`.
    Atan2([ExprId; 2]),
}

impl Node {
    /// The children of this node, in order.
    pub fn children(&self) -> &[ExprId] {
        match self {
            Node::Const(_) | Node::Pi | Node::Symbol(_) => &[],
            Node::Add(c) | Node::Mul(c) => c,
            Node::Pow(c) | Node::Atan2(c) => c,
            Node::Func(_, c) => std::slice::from_ref(c),
        }
    }

    /// The node as a [`NodeRef`] (same hash, same equality).
    fn as_ref(&self) -> NodeRef<'_> {
        match self {
            Node::Const(c) => NodeRef::Const(*c),
            Node::Pi => NodeRef::Pi,
            Node::Symbol(s) => NodeRef::Symbol(*s),
            Node::Add(c) => NodeRef::Add(c),
            Node::Mul(c) => NodeRef::Mul(c),
            Node::Pow(c) => NodeRef::Pow(*c),
            Node::Func(f, u) => NodeRef::Func(*f, *u),
            Node::Atan2(c) => NodeRef::Atan2(*c),
        }
    }
}

impl std::hash::Hash for Node {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.as_ref().hash(state);
    }
}

/// A [`Node`] whose children are borrowed, to look nodes up in the hash-cons table without
/// allocating one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum NodeRef<'a> {
    Const(Constant),
    Pi,
    Symbol(SymbolId),
    Add(&'a [ExprId]),
    Mul(&'a [ExprId]),
    Pow([ExprId; 2]),
    Func(Func, ExprId),
    Atan2([ExprId; 2]),
}

impl NodeRef<'_> {
    /// An owned copy.
    fn to_node(self) -> Node {
        match self {
            NodeRef::Const(c) => Node::Const(c),
            NodeRef::Pi => Node::Pi,
            NodeRef::Symbol(s) => Node::Symbol(s),
            NodeRef::Add(c) => Node::Add(c.into()),
            NodeRef::Mul(c) => Node::Mul(c.into()),
            NodeRef::Pow(c) => Node::Pow(c),
            NodeRef::Func(f, u) => Node::Func(f, u),
            NodeRef::Atan2(c) => Node::Atan2(c),
        }
    }
}

impl indexmap::Equivalent<Node> for NodeRef<'_> {
    fn equivalent(&self, key: &Node) -> bool {
        *self == key.as_ref()
    }
}

/// What a symbol stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    /// A model parameter (constant in time).
    Parameter,
    /// Generalized coordinate `q_i`.
    Coordinate(u32),
    /// Generalized velocity `q̇_i`.
    Velocity(u32),
    /// Generalized acceleration `q̈_i`.
    Acceleration(u32),
    /// Time `t`.
    Time,
    /// Any other symbol (constant in time), e.g. the vector `a` of `∂(M a)/∂q`.
    Auxiliary,
    /// The Lagrange multiplier (constraint force) `λ_i` of constraint `i` (holonomic first),
    /// `lambda_<constraint>`: only in event functions.
    Multiplier(u32),
    /// A coordinate's rate `q̇ᵢ` or acceleration `q̈ᵢ` in a model whose state holds
    /// generalized speeds ([`ExprArena::switch_to_speeds`]): replaced by the kinematic
    /// equations in every expression of the model, so never in generated code.
    Retired,
}

/// A named symbol.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Symbol {
    /// Its name (`theta1`, `theta1_dot`, `t`).
    pub name: String,
    /// What it stands for.
    pub kind: SymbolKind,
}

/// Owns every node and symbol; builds canonical, hash-consed expressions.
#[derive(Debug, Default, Clone)]
pub struct ExprArena {
    /// Every node once; a node's index is its [`ExprId`] (the hash-cons table and the node
    /// list in one).
    nodes: indexmap::IndexSet<Node, rustc_hash::FxBuildHasher>,
    symbols: Vec<Symbol>,
    symbol_ids: FxHashMap<String, SymbolId>,
    /// `(q_i, q̇_i, q̈_i)` symbol ids per coordinate, in coordinate order.
    coordinates: Vec<[SymbolId; 3]>,
    time: Option<SymbolId>,
    /// Per node, a 128-bit summary of the symbols it contains (bit `id mod 128` of each
    /// symbol): a clear bit proves independence, so [`Self::diff`] and [`Self::depends_on`]
    /// answer most queries without walking the sub-DAG.
    symbol_bits: Vec<u128>,
    /// Per node, whether it contains a time-varying symbol (see [`Self::is_time_varying`]).
    time_varying: Vec<bool>,
    /// Per node, its operation count as a tree (saturating), so that
    /// [`Self::tree_operation_count`] costs one lookup per root.
    tree_costs: Vec<u64>,
    diff_memo: FxHashMap<(ExprId, SymbolId), ExprId>,
    dt_memo: FxHashMap<ExprId, ExprId>,
    /// With generalized speeds, `q̇ᵢ` as expressions of `q`, the speeds and `t` (the
    /// kinematic equations), which [`Self::time_derivative`] uses; `None`: the rate symbols.
    coordinate_rates: Option<Vec<ExprId>>,
    expand_memo: FxHashMap<ExprId, ExprId>,
    expand_time_varying_memo: FxHashMap<ExprId, ExprId>,
    expand_bounded_memo: FxHashMap<ExprId, ExprId>,
    /// What each expansion would produce, per node and mode (`expand`'s caps).
    expansion_shapes: FxHashMap<(ExprId, expand::Expansion), expand::Shape>,
    /// Canonical sums of two terms, by their (ordered) terms: collecting a chain adds one mass
    /// to the same long sum of masses once per joint above it, and each such sum would
    /// otherwise flatten, sort and merge the long one again.
    pair_sum_memo: FxHashMap<(ExprId, ExprId), ExprId>,
    /// The nodes of the integers −1, 0, 1 and 2 once created: every derivative that vanishes
    /// and every negation asks for one, and a hash-cons lookup per request was a tenth of a
    /// long chain's Lagrange derivation.
    small_ints: [Option<ExprId>; 4],
    /// The first fold of constants since the last [`Self::take_fold_error`] whose value
    /// cannot be a node (a product or sum of constants beyond ±1.8e308, a product of non-zero
    /// ones that underflows to 0, a power that is not real): the fold is then not done, the
    /// numbers are kept apart as they were written, and lowering a model file asks whether
    /// the numbers written in the operation alone fail (a located error) or only a rewrite
    /// would have.
    fold_error: std::cell::Cell<Option<FoldError>>,
    /// The operands of every node created (a node of `k` children counts `k`): the size of
    /// what the arena holds, and the measure [`Self::limit_operands`] bounds.
    operands: u64,
    /// See [`Self::limit_operands`].
    operand_limit: Option<u64>,
}

impl ExprArena {
    /// An empty arena.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the arena has no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Bounds a derivation that would not end in reasonable time and memory (a guard for what
    /// the expansion's caps miss; before them, a chain of 3-D frames nested in relative
    /// rotations grew about 15× per level): once
    /// the nodes created hold more than `limit` operands in all ([`Self::operands`]), every
    /// sum and product built is 0, so the derivation runs to its end quickly, and
    /// [`Self::over_limit`] is true. Its expressions are then meaningless: the caller reports the limit instead of
    /// using them. `None` lifts the limit (the arena's default); the limit does not undo
    /// what was built.
    pub fn limit_operands(&mut self, limit: Option<u64>) {
        self.operand_limit = limit;
    }

    /// Whether the limit of [`Self::limit_operands`] was passed, and the arena's expressions
    /// since are not to be used.
    pub fn over_limit(&self) -> bool {
        self.operand_limit
            .is_some_and(|limit| self.operands > limit)
    }

    /// The operands of every node created so far (a node of `k` children counts `k`).
    pub fn operands(&self) -> u64 {
        self.operands
    }

    /// Why folding constants failed since the last call, if it did (and clears it): a
    /// value beyond `f64` or lost to underflow ([`FoldError`]). The fold was then not done:
    /// the expression built keeps those numbers apart, with the value asked for, and its
    /// caller decides whether the numbers as written are an error.
    pub fn take_fold_error(&mut self) -> Option<FoldError> {
        self.fold_error.take()
    }

    /// Records the first failed fold since the last [`Self::take_fold_error`].
    fn fold_failed(&self, e: FoldError) {
        if self.fold_error.get().is_none() {
            self.fold_error.set(Some(e));
        }
    }

    /// The node behind `id`.
    pub fn node(&self, id: ExprId) -> &Node {
        &self.nodes[id.index()]
    }

    /// The symbol table, indexed by [`SymbolId`].
    pub fn symbols(&self) -> &[Symbol] {
        &self.symbols
    }

    /// The symbol behind `id`.
    pub fn symbol_info(&self, id: SymbolId) -> &Symbol {
        &self.symbols[id.index()]
    }

    /// The symbol id of `name`, if declared.
    pub fn symbol_id(&self, name: &str) -> Option<SymbolId> {
        self.symbol_ids.get(name).copied()
    }

    /// Declares (or finds) a symbol and returns its expression.
    ///
    /// # Panics
    /// If `name` was declared before with a different kind (a programmer error: the model
    /// checks reject duplicate names).
    pub fn symbol(&mut self, name: &str, kind: SymbolKind) -> ExprId {
        let id = self.declare(name, kind);
        self.add(Node::Symbol(id))
    }

    /// Declares (or finds) a symbol and returns its id ([`symbol`](Self::symbol) without the
    /// expression).
    ///
    /// # Panics
    /// As [`symbol`](Self::symbol).
    pub fn declare(&mut self, name: &str, kind: SymbolKind) -> SymbolId {
        match self.symbol_ids.get(name) {
            Some(&id) => {
                assert_eq!(
                    self.symbols[id.index()].kind,
                    kind,
                    "symbol `{name}` redeclared"
                );
                id
            }
            None => {
                let id = SymbolId(self.symbols.len() as u32);
                self.symbols.push(Symbol {
                    name: name.to_string(),
                    kind,
                });
                self.symbol_ids.insert(name.to_string(), id);
                if kind == SymbolKind::Time {
                    self.time = Some(id);
                }
                id
            }
        }
    }

    /// Declares generalized coordinate number `coordinates().len()` named `name`, with its
    /// rate `name_dot` and acceleration `name_ddot`; returns `[q, q̇, q̈]`.
    pub fn coordinate(&mut self, name: &str) -> [ExprId; 3] {
        let i = self.coordinates.len() as u32;
        let ids = [
            self.declare(name, SymbolKind::Coordinate(i)),
            self.declare(&format!("{name}_dot"), SymbolKind::Velocity(i)),
            self.declare(&format!("{name}_ddot"), SymbolKind::Acceleration(i)),
        ];
        self.coordinates.push(ids);
        ids.map(|id| self.add(Node::Symbol(id)))
    }

    /// Makes the speeds `names` (one per coordinate) the state's second half: declares each
    /// speed `uᵣ` (kind [`SymbolKind::Velocity`]) and its rate `uᵣ_dot`
    /// ([`SymbolKind::Acceleration`]), puts them in the coordinates' triples in place of
    /// `q̇ᵣ` and `q̈ᵣ`, which become [`SymbolKind::Retired`]; returns the new `[u, u̇]`
    /// expressions per coordinate. The caller then gives the kinematic
    /// equations ([`Self::set_coordinate_rates`]) and replaces `q̇` and `q̈` in every
    /// expression it keeps.
    ///
    /// # Panics
    /// If `names` is not one per coordinate or a name (or its `_dot`) is declared already
    /// (the model checks reject both, and the model's switch says so before calling).
    pub fn switch_to_speeds(&mut self, names: &[String]) -> Vec<[ExprId; 2]> {
        assert_eq!(
            names.len(),
            self.coordinates.len(),
            "one speed per coordinate"
        );
        let mut out = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            assert!(
                self.symbol_id(name).is_none(),
                "speed `{name}` declared twice"
            );
            let [_, qd, qdd] = self.coordinates[i];
            for old in [qd, qdd] {
                self.symbols[old.index()].kind = SymbolKind::Retired;
            }
            let u = self.declare(name, SymbolKind::Velocity(i as u32));
            let ud = self.declare(&format!("{name}_dot"), SymbolKind::Acceleration(i as u32));
            self.coordinates[i][1] = u;
            self.coordinates[i][2] = ud;
            out.push([u, ud].map(|s| self.symbol_expr(s)));
        }
        self.dt_memo.clear();
        out
    }

    /// The kinematic equations `q̇ᵢ = rates[i]` of a model whose state holds generalized
    /// speeds ([`Self::switch_to_speeds`]), for [`Self::time_derivative`].
    pub fn set_coordinate_rates(&mut self, rates: Vec<ExprId>) {
        self.coordinate_rates = Some(rates);
        self.dt_memo.clear();
    }

    /// `q̇ᵢ`: the rate symbol, or with generalized speeds the kinematic equation's right side.
    pub fn coordinate_rate(&mut self, i: usize) -> ExprId {
        match &self.coordinate_rates {
            Some(rates) => rates[i],
            None => self.symbol_expr(self.coordinates[i][1]),
        }
    }

    /// `(q, q̇, q̈)` symbol ids per coordinate (with generalized speeds, `(q, u, u̇)`).
    pub fn coordinates(&self) -> &[[SymbolId; 3]] {
        &self.coordinates
    }

    /// The time symbol `t` (declared on first use).
    pub fn time(&mut self) -> ExprId {
        self.symbol("t", SymbolKind::Time)
    }

    /// The id of the time symbol `t` (declared on first use).
    pub fn time_id(&mut self) -> SymbolId {
        self.declare("t", SymbolKind::Time)
    }

    /// Expression for the symbol `id`.
    pub fn symbol_expr(&mut self, id: SymbolId) -> ExprId {
        self.add(Node::Symbol(id))
    }

    /// Interns `node` as is (no canonicalisation): the same node always gets the same id.
    ///
    /// Callers building arithmetic should use [`Self::sum`], [`Self::product`], [`Self::pow`]
    /// etc., which canonicalise first.
    pub fn add(&mut self, node: Node) -> ExprId {
        let (index, new) = self.nodes.insert_full(node);
        let id = ExprId(index as u32);
        if !new {
            return id;
        }
        let node = &self.nodes[index];
        self.operands += node.children().len() as u64;
        debug_assert!(
            node.children().iter().all(|c| *c < id),
            "children must precede parents"
        );
        let (bits, varying, cost) = match *node {
            Node::Symbol(s) => (symbol_bit(s), self.is_time_varying(s), 0),
            _ => node.children().iter().fold(
                (0, false, node_operation_count(node)),
                |(bits, varying, cost), c| {
                    (
                        bits | self.symbol_bits[c.index()],
                        varying || self.time_varying[c.index()],
                        cost.saturating_add(self.tree_costs[c.index()]),
                    )
                },
            ),
        };
        self.symbol_bits.push(bits);
        self.time_varying.push(varying);
        self.tree_costs.push(cost);
        id
    }

    /// The id of `node` if it is in the arena.
    fn lookup(&self, node: NodeRef<'_>) -> Option<ExprId> {
        self.nodes.get_index_of(&node).map(|i| ExprId(i as u32))
    }

    /// [`Self::add`] of a borrowed node, which allocates only if the node is new.
    fn add_ref(&mut self, node: NodeRef<'_>) -> ExprId {
        match self.lookup(node) {
            Some(id) => id,
            None => self.add(node.to_node()),
        }
    }

    /// A constant.
    pub fn constant(&mut self, c: Constant) -> ExprId {
        self.add(Node::Const(c))
    }

    /// The integer `n`.
    pub fn int(&mut self, n: i64) -> ExprId {
        let slot = n
            .checked_add(1)
            .and_then(|k| usize::try_from(k).ok())
            .filter(|k| *k < self.small_ints.len());
        let Some(slot) = slot else {
            return self.constant(Constant::int(n));
        };
        if let Some(id) = self.small_ints[slot] {
            return id;
        }
        let id = self.constant(Constant::int(n));
        self.small_ints[slot] = Some(id);
        id
    }

    /// A float constant; non-finite values become NaN-free by clamping to the largest finite
    /// value of the same sign (they cannot arise from model files, which the checks reject).
    pub fn float(&mut self, x: f64) -> ExprId {
        let c = Constant::float(x).unwrap_or_else(|| {
            Constant::float(if x > 0.0 { f64::MAX } else { f64::MIN }).unwrap_or(Constant::ZERO)
        });
        self.constant(c)
    }

    /// π.
    pub fn pi(&mut self) -> ExprId {
        self.add(Node::Pi)
    }

    /// The constant value of `id`, if it is a number.
    pub fn as_constant(&self, id: ExprId) -> Option<Constant> {
        match self.node(id) {
            Node::Const(c) => Some(*c),
            _ => None,
        }
    }

    /// Whether `id` is the number zero.
    pub fn is_zero(&self, id: ExprId) -> bool {
        self.as_constant(id).is_some_and(Constant::is_zero)
    }

    /// `a + b`.
    pub fn plus(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.sum(&[a, b])
    }

    /// `a · b`.
    pub fn times(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.product(&[a, b])
    }

    /// `-a`.
    pub fn neg(&mut self, a: ExprId) -> ExprId {
        let m = self.int(-1);
        self.product(&[m, a])
    }

    /// `a - b`.
    pub fn minus(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let nb = self.neg(b);
        self.sum(&[a, nb])
    }

    /// `a / b`.
    pub fn divide(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let m = self.int(-1);
        let inv = self.pow(b, m);
        self.product(&[a, inv])
    }

    /// `√a` as `a^(1/2)`.
    pub fn sqrt(&mut self, a: ExprId) -> ExprId {
        let half = self.constant(Constant::Rational { num: 1, den: 2 });
        self.pow(a, half)
    }

    /// Canonical `base ^ exponent`.
    pub fn pow(&mut self, base: ExprId, exponent: ExprId) -> ExprId {
        let e = self.as_constant(exponent);
        if let Some(e) = e {
            if e.is_zero() {
                return self.int(1);
            }
            if e.is_one() {
                return base;
            }
        }
        if let Some(b) = self.as_constant(base) {
            if b.is_one() {
                return self.int(1);
            }
            if let Some(e) = e {
                match b.pow(e) {
                    Ok(Some(v)) => return self.constant(v),
                    Ok(None) => {}
                    // Kept as a power; the caller reports the fold.
                    Err(error) => self.fold_failed(error),
                }
            }
            if b.is_zero() && e.is_some_and(|e| !e.is_negative()) {
                return self.int(0);
            }
        }
        let integer_exponent = e.and_then(Constant::as_integer);
        match self.node(base).clone() {
            // (x^a)^n = x^(a n) for integer n.
            Node::Pow([b, a]) if integer_exponent.is_some() => {
                let product = self.times(a, exponent);
                return self.pow(b, product);
            }
            // (x y)^n = x^n y^n for integer n, unless a number among the factors would
            // overflow or underflow to the n-th power: `(1e-20 x)^16` stays as it is written,
            // which evaluates well for x near 1e20, where 1e-320 · x^16 would be 0 · ∞.
            Node::Mul(factors)
                if integer_exponent.is_some()
                    && factors.iter().all(|&f| {
                        self.as_constant(f)
                            .is_none_or(|c| c.pow(e.unwrap_or(Constant::ONE)).is_ok())
                    }) =>
            {
                let powered: Vec<ExprId> = factors.iter().map(|&f| self.pow(f, exponent)).collect();
                return self.product(&powered);
            }
            _ => {}
        }
        self.add(Node::Pow([base, exponent]))
    }

    /// If `arg = c · rest` with `c < 0`, returns `-arg` (= `|c| · rest`).
    fn negated_if_negative(&mut self, arg: ExprId) -> Option<ExprId> {
        let (c, rest) = self.split_coefficient(arg);
        if c.is_negative() {
            let positive = self.constant(c.negated());
            Some(match rest {
                Some(r) => self.times(positive, r),
                None => positive,
            })
        } else {
            None
        }
    }

    /// Canonical `f(arg)`.
    pub fn func(&mut self, f: Func, arg: ExprId) -> ExprId {
        if let Some(c) = self.as_constant(arg) {
            if c.is_zero() {
                return match f {
                    Func::Cos | Func::Cosh | Func::Exp | Func::Step => self.int(1),
                    Func::Acos => {
                        let pi = self.pi();
                        let half = self.constant(Constant::Rational { num: 1, den: 2 });
                        self.times(half, pi)
                    }
                    Func::Ln => self.add(Node::Func(f, arg)),
                    _ => self.int(0),
                };
            }
            if matches!(f, Func::Abs | Func::Sign | Func::Step) {
                let v = f.apply(c.to_f64());
                return self.float(v);
            }
        }
        if (f.is_odd() || f.is_even())
            && let Some(positive) = self.negated_if_negative(arg)
        {
            let inner = self.func(f, positive);
            return if f.is_odd() { self.neg(inner) } else { inner };
        }
        self.add(Node::Func(f, arg))
    }

    /// `sin(a)`.
    pub fn sin(&mut self, a: ExprId) -> ExprId {
        self.func(Func::Sin, a)
    }

    /// `cos(a)`.
    pub fn cos(&mut self, a: ExprId) -> ExprId {
        self.func(Func::Cos, a)
    }

    /// `atan2(y, x)`.
    pub fn atan2(&mut self, y: ExprId, x: ExprId) -> ExprId {
        self.add(Node::Atan2([y, x]))
    }

    /// Whether `expr` may contain the symbol `s`: `false` proves that it does not (one
    /// lookup); `true` may be a false positive (another symbol with the same id mod 128).
    pub(crate) fn may_depend_on(&self, expr: ExprId, s: SymbolId) -> bool {
        self.symbol_bits[expr.index()] & symbol_bit(s) != 0
    }

    /// Whether `expr` contains a symbol that changes in time (coordinate, rate, acceleration
    /// or `t`); one lookup.
    pub fn contains_time_varying(&self, expr: ExprId) -> bool {
        self.time_varying[expr.index()]
    }

    /// Whether `expr` contains the symbol `s` (walks the sub-DAG at most once).
    pub fn depends_on(&self, expr: ExprId, s: SymbolId) -> bool {
        if !self.may_depend_on(expr, s) {
            return false;
        }
        let Some(sid) = self.lookup(NodeRef::Symbol(s)) else {
            return false;
        };
        if sid > expr {
            return false;
        }
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack = vec![expr];
        while let Some(e) = stack.pop() {
            if e == sid {
                return true;
            }
            if e < sid || !seen.insert(e) {
                continue;
            }
            stack.extend(self.node(e).children().iter().copied());
        }
        false
    }

    /// Every node reachable from `roots`, in ascending id order (a topological order).
    pub fn reachable(&self, roots: &[ExprId]) -> Vec<ExprId> {
        let mut mark = vec![false; self.nodes.len()];
        let mut stack: Vec<ExprId> = roots.to_vec();
        while let Some(e) = stack.pop() {
            if std::mem::replace(&mut mark[e.index()], true) {
                continue;
            }
            stack.extend(self.node(e).children().iter().copied());
        }
        mark.iter()
            .enumerate()
            .filter(|(_, m)| **m)
            .map(|(i, _)| ExprId(i as u32))
            .collect()
    }

    /// Number of arithmetic operations to evaluate `roots` as trees (no sharing), saturating:
    /// a sum or product of `k` operands counts `k − 1`, a power or function call 1.
    pub fn tree_operation_count(&self, roots: &[ExprId]) -> u64 {
        roots.iter().fold(0u64, |acc, r| {
            acc.saturating_add(self.tree_costs[r.index()])
        })
    }
}

/// The bit of symbol `s` in [`ExprArena`]'s per-node symbol summaries.
fn symbol_bit(s: SymbolId) -> u128 {
    1 << (s.0 % 128)
}

/// Operations a node costs by itself.
pub(crate) fn node_operation_count(node: &Node) -> u64 {
    match node {
        Node::Const(_) | Node::Pi | Node::Symbol(_) => 0,
        Node::Add(c) | Node::Mul(c) => c.len() as u64 - 1,
        Node::Pow(_) | Node::Func(..) | Node::Atan2(_) => 1,
    }
}

#[cfg(test)]
mod tests;
