//! Solving each holonomic constraint for the coordinate it eliminates: a polynomial of degree one
//! or two in it (after rationalising square roots), and the branch the initial state, an
//! equilibrium or the options choose.

use super::*;

impl Reducer<'_> {
    /// Solves the constraints for the coordinates `dependent`, one at a time.
    pub(super) fn solve(
        &mut self,
        dependent: &[usize],
        options: &ReduceOptions,
    ) -> Result<Vec<Elimination>, ReduceError> {
        let mut constraints: Vec<(String, ExprId)> = Vec::new();
        for (name, e) in &self.file.constraints {
            let phi = self.lower_in(e, &format!("constraint `{}`", name.value))?;
            constraints.push((name.value.clone(), phi));
        }
        let mut unsolved: Vec<usize> = dependent.to_vec();
        // The solutions so far, in terms of the kept and the still unsolved coordinates.
        let mut solved: FxHashMap<SymbolId, ExprId> = FxHashMap::default();
        let mut eliminations: Vec<(usize, Elimination, ExprId)> = Vec::new();
        while !unsolved.is_empty() {
            let (k, i, (elimination, root)) =
                self.next_elimination(&constraints, &unsolved, &solved, options)?;
            let q = self.coordinates[i][0];
            let one: FxHashMap<SymbolId, ExprId> = [(q, root)].into_iter().collect();
            for v in solved.values_mut() {
                *v = self.arena.substitute(*v, &one);
            }
            solved.insert(q, root);
            constraints.remove(k);
            unsolved.retain(|&j| j != i);
            eliminations.push((i, elimination, root));
        }
        Ok(self.finish_eliminations(eliminations, &solved))
    }

    /// Finds the next constraint to solve and the coordinate it eliminates (the constraints
    /// with the fewest unsolved coordinates first, with `solved` substituted): its index in
    /// `constraints`, the coordinate's index, the elimination and its solution; otherwise the
    /// first failure met.
    fn next_elimination(
        &mut self,
        constraints: &[(String, ExprId)],
        unsolved: &[usize],
        solved: &FxHashMap<SymbolId, ExprId>,
        options: &ReduceOptions,
    ) -> Result<(usize, usize, (Elimination, ExprId)), ReduceError> {
        let mut first_failure: Option<ReduceError> = None;
        let mut found = None;
        // Constraints with the fewest unsolved coordinates first.
        let mut order: Vec<(usize, Vec<usize>, ExprId)> = Vec::new();
        for (k, (_, phi)) in constraints.iter().enumerate() {
            let phi = self.arena.substitute(*phi, solved);
            let involved: Vec<usize> = unsolved
                .iter()
                .copied()
                .filter(|&i| self.arena.depends_on(phi, self.coordinates[i][0]))
                .collect();
            order.push((k, involved, phi));
        }
        order.sort_by_key(|(_, inv, _)| inv.len());
        'search: for (k, involved, phi) in &order {
            if involved.is_empty() {
                let (name, _) = &constraints[*k];
                let coordinate = self.file.coordinates[unsolved[0]].name.value.clone();
                first_failure.get_or_insert(ReduceError::Unsolvable {
                    constraint: name.clone(),
                    coordinate,
                    reason: "the constraint does not contain the coordinates to eliminate \
                             (after the others are substituted): it constrains the kept \
                             coordinates alone; keep other coordinates"
                        .to_string(),
                });
                continue;
            }
            for &i in involved {
                match self.solve_one(&constraints[*k].0, *phi, i, options) {
                    Ok(found_one) => {
                        found = Some((*k, i, found_one));
                        break 'search;
                    }
                    Err(e) => {
                        first_failure.get_or_insert(e);
                    }
                }
            }
        }
        let Some(found) = found else {
            return Err(first_failure.unwrap_or_else(|| ReduceError::Unsolvable {
                constraint: constraints[0].0.clone(),
                coordinate: self.file.coordinates[unsolved[0]].name.value.clone(),
                reason: "no constraint contains it".to_string(),
            }));
        };
        Ok(found)
    }

    /// Records the eliminations, in the order solved: their solutions in the kept coordinates
    /// alone (`solved`) and their rates by the chain rule, the names they remove, and the
    /// singularity expressions in the kept coordinates.
    fn finish_eliminations(
        &mut self,
        eliminations: Vec<(usize, Elimination, ExprId)>,
        solved: &FxHashMap<SymbolId, ExprId>,
    ) -> Vec<Elimination> {
        // Solutions in the kept coordinates alone, and their rates by the chain rule.
        let mut out = Vec::new();
        for (i, mut elimination, _) in eliminations {
            let [q, qd, _] = self.coordinates[i];
            let root = solved[&q];
            let rate = self.arena.time_derivative(root);
            let rate = self.arena.expand_if_cheaper(rate);
            elimination.solution = self.print(root);
            elimination.rate = self.print(rate);
            self.values.insert(q, root);
            self.values.insert(qd, rate);
            let name = &self.file.coordinates[i].name.value;
            self.eliminated_names.extend([
                name.clone(),
                format!("{name}_dot"),
                format!("{name}_ddot"),
            ]);
            out.push(elimination);
        }
        self.eliminated_names.extend(
            self.file
                .constraints
                .iter()
                .map(|(c, _)| format!("lambda_{}", c.value)),
        );
        // The singularity expressions in the kept coordinates too.
        for (_, e, _) in &mut self.singular_where {
            *e = self.arena.substitute(*e, solved);
        }
        out
    }

    /// Solves `phi = 0` for coordinate `i`.
    fn solve_one(
        &mut self,
        constraint: &str,
        phi: ExprId,
        i: usize,
        options: &ReduceOptions,
    ) -> Result<(Elimination, ExprId), ReduceError> {
        let coordinate = self.file.coordinates[i].name.value.clone();
        let d = self.coordinates[i][0];
        let fail = |reason: String| ReduceError::Unsolvable {
            constraint: constraint.to_string(),
            coordinate: coordinate.clone(),
            reason,
        };
        for rate in &self.coordinates[i][1..] {
            if self.arena.depends_on(phi, *rate) {
                return Err(fail("the constraint contains its rate".to_string()));
            }
        }
        let (polynomial, squared) = match polynomial_degree(&self.arena, phi, d) {
            Ok(_) => (phi, false),
            Err(at) => match self.rationalize(phi, d) {
                Some(p) => (p, true),
                None => {
                    return Err(fail(format!(
                        "`{coordinate}` appears in `{}`, which is not polynomial in it; the \
                         elimination solves constraints that are polynomials of degree ≤ 2 in \
                         the coordinate (or become one when a square root is squared), so \
                         `{coordinate}` can only be kept",
                        self.print(at)
                    )));
                }
            },
        };
        let Some(coefficients) = coefficients(&mut self.arena, polynomial, d) else {
            return Err(fail(
                "the constraint is not polynomial in it once multiplied out".to_string(),
            ));
        };
        let degree = coefficients.len().saturating_sub(1);
        let found = match degree {
            0 => {
                return Err(fail(
                    "the coordinate cancels from the constraint once multiplied out".to_string(),
                ));
            }
            1 => {
                let (c0, c1) = (coefficients[0], coefficients[1]);
                let minus_c0 = self.arena.neg(c0);
                let root = self.arena.divide(minus_c0, c1);
                let root = self.arena.expand_if_cheaper(root);
                Roots::Linear { root, slope: c1 }
            }
            2 => self.quadratic(coefficients[2], coefficients[1], coefficients[0]),
            n => {
                return Err(fail(format!(
                    "the constraint is of degree {n} in it; the elimination solves degree 1 and 2"
                )));
            }
        };
        let (root, branch, singular) = match found {
            Roots::Linear { root, slope } => (root, None, (slope, false)),
            Roots::Quadratic {
                plus,
                minus,
                discriminant,
            } => {
                let (branch, reason) =
                    self.choose_branch(&coordinate, phi, d, [plus, minus], options)?;
                let root = if branch == Branch::Plus { plus } else { minus };
                (root, Some((branch, reason)), (discriminant, true))
            }
        };
        self.singular_where
            .push((coordinate.clone(), singular.0, singular.1));
        Ok((
            Elimination {
                coordinate,
                constraint: constraint.to_string(),
                solution: String::new(),
                rate: String::new(),
                degree: degree as u32,
                squared,
                branch,
            },
            root,
        ))
    }

    /// The two roots of `a d² + b d + c = 0`.
    pub(super) fn quadratic(&mut self, a: ExprId, b: ExprId, c: ExprId) -> Roots {
        // d = −h ± √(h² − c/a) with h = b/(2a): the radicand multiplied out is the
        // discriminant over 4a², free of the factor 4 that (−b ± √(b² − 4ac))/(2a) leaves
        // under the root (`l^2 - x^2` rather than `4*l^2 - 4*x^2`).
        let ar = &mut self.arena;
        let two = ar.int(2);
        let two_a = ar.times(two, a);
        let h = ar.divide(b, two_a);
        let h = ar.expand_if_cheaper(h);
        let h2 = ar.times(h, h);
        let c_over_a = ar.divide(c, a);
        let radicand = ar.minus(h2, c_over_a);
        let radicand = ar.expand(radicand);
        let root = ar.sqrt(radicand);
        let minus_h = ar.neg(h);
        let plus = ar.plus(minus_h, root);
        let minus = ar.minus(minus_h, root);
        Roots::Quadratic {
            plus,
            minus,
            discriminant: radicand,
        }
    }

    /// `k² P − R²` for `phi = k √P + R` with `P` polynomial in `d` and `k`, `R` free of it.
    fn rationalize(&mut self, phi: ExprId, d: SymbolId) -> Option<ExprId> {
        let terms: Vec<ExprId> = match self.arena.node(phi) {
            Node::Add(t) => t.to_vec(),
            _ => vec![phi],
        };
        let (with, without): (Vec<ExprId>, Vec<ExprId>) = terms
            .into_iter()
            .partition(|&t| self.arena.depends_on(t, d));
        let [term] = with.as_slice() else {
            return None;
        };
        let factors: Vec<ExprId> = match self.arena.node(*term) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![*term],
        };
        let (root, k): (Vec<ExprId>, Vec<ExprId>) = factors
            .into_iter()
            .partition(|&f| self.arena.depends_on(f, d));
        let [root] = root.as_slice() else {
            return None;
        };
        let Node::Pow([p, half]) = *self.arena.node(*root) else {
            return None;
        };
        if self.arena.as_constant(half).map(Constant::to_f64) != Some(0.5)
            || polynomial_degree(&self.arena, p, d).is_err()
        {
            return None;
        }
        let ar = &mut self.arena;
        let k = ar.product(&k);
        let r = ar.sum(&without);
        let k2 = ar.times(k, k);
        let k2p = ar.times(k2, p);
        let r2 = ar.times(r, r);
        let squared = ar.minus(k2p, r2);
        Some(ar.expand(squared))
    }

    /// The branch of a quadratic solution (see the module documentation). `phi` is the
    /// constraint as written (after earlier substitutions), which the root must satisfy.
    fn choose_branch(
        &mut self,
        coordinate: &str,
        phi: ExprId,
        d: SymbolId,
        roots: [ExprId; 2],
        options: &ReduceOptions,
    ) -> Result<(Branch, BranchReason), ReduceError> {
        if let Some((_, b)) = options.branches.iter().find(|(n, _)| n == coordinate) {
            return Ok((*b, BranchReason::Option));
        }
        let decide = |this: &Self, bindings: &mut Vec<f64>| -> Option<Branch> {
            let value = bindings[d.index()];
            let mut on = [false; 2];
            let mut r = [0.0; 2];
            for (k, &root) in roots.iter().enumerate() {
                r[k] = this.arena.eval(root, bindings);
                let saved = bindings[d.index()];
                bindings[d.index()] = r[k];
                let residual = this.arena.eval(phi, bindings);
                bindings[d.index()] = saved;
                let scale = BRANCH_TOL * r[k].abs().max(1.0);
                on[k] = r[k].is_finite()
                    && residual.abs() <= scale
                    && (r[k] - value).abs() <= scale.max(1e-6 * value.abs());
            }
            let distinct = (r[0] - r[1]).abs() > BRANCH_TOL * r[0].abs().max(r[1].abs()).max(1.0);
            match (on, distinct) {
                ([true, false], true) => Some(Branch::Plus),
                ([false, true], true) => Some(Branch::Minus),
                _ => None,
            }
        };
        let mut start = self.bindings(&self.file.initial);
        if let Some(b) = decide(self, &mut start) {
            return Ok((b, BranchReason::InitialState));
        }
        // A start given as `{ guess: … }` is only near the constraint: the root nearest it
        // among those on the constraint as written (the one the start's projection finds).
        if self
            .file
            .initial_guesses
            .iter()
            .any(|g| g.value == coordinate)
        {
            let guess = start[d.index()];
            let mut near: Vec<(f64, Branch)> = Vec::new();
            for (root, branch) in roots.iter().zip([Branch::Plus, Branch::Minus]) {
                let r = self.arena.eval(*root, &start);
                start[d.index()] = r;
                let residual = self.arena.eval(phi, &start);
                start[d.index()] = guess;
                if r.is_finite() && residual.abs() <= BRANCH_TOL * r.abs().max(1.0) {
                    near.push(((r - guess).abs(), branch));
                }
            }
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            match near.as_slice() {
                [(_, b)] => return Ok((*b, BranchReason::InitialState)),
                [(da, b), (db, _)] if db - da > BRANCH_TOL * (da + db).max(1.0) => {
                    return Ok((*b, BranchReason::InitialState));
                }
                _ => {}
            }
        }
        for eq in &self.file.equilibria {
            let mut at = self.bindings(&eq.values);
            if let Some(b) = decide(self, &mut at) {
                return Ok((b, BranchReason::Equilibrium(eq.name.value.clone())));
            }
        }
        Err(ReduceError::AmbiguousBranch {
            coordinate: coordinate.to_string(),
            plus: self.print(roots[0]),
            minus: self.print(roots[1]),
        })
    }
}

/// The degree of `e` in `d` if `d` appears only in sums, products and powers with
/// non-negative integer exponents; else the first sub-expression where it appears otherwise.
fn polynomial_degree(arena: &ExprArena, e: ExprId, d: SymbolId) -> Result<u32, ExprId> {
    if !arena.depends_on(e, d) {
        return Ok(0);
    }
    match arena.node(e) {
        Node::Symbol(s) if *s == d => Ok(1),
        Node::Add(terms) => terms
            .iter()
            .try_fold(0, |m, &t| polynomial_degree(arena, t, d).map(|k| m.max(k))),
        Node::Mul(factors) => factors.iter().try_fold(0u32, |m, &f| {
            polynomial_degree(arena, f, d).map(|k| m.saturating_add(k))
        }),
        Node::Pow([b, x]) => match arena.as_constant(*x).and_then(Constant::as_integer) {
            Some(k) if (0..=64).contains(&k) && !arena.depends_on(*x, d) => {
                polynomial_degree(arena, *b, d).map(|m| m.saturating_mul(k as u32))
            }
            _ => Err(e),
        },
        _ => Err(e),
    }
}

/// The coefficients `[c₀, c₁, …]` of `e` as a polynomial in `d` (multiplied out), or `None`
/// if a term of the multiplied-out form is not a monomial in `d`.
fn coefficients(arena: &mut ExprArena, e: ExprId, d: SymbolId) -> Option<Vec<ExprId>> {
    let e = arena.expand(e);
    let terms: Vec<ExprId> = match arena.node(e) {
        Node::Add(t) => t.to_vec(),
        _ => vec![e],
    };
    let mut by_power: Vec<Vec<ExprId>> = Vec::new();
    for t in terms {
        let factors: Vec<ExprId> = match arena.node(t) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![t],
        };
        let mut power = 0usize;
        let mut rest = Vec::new();
        for f in factors {
            if !arena.depends_on(f, d) {
                rest.push(f);
                continue;
            }
            match arena.node(f) {
                Node::Symbol(s) if *s == d => power += 1,
                Node::Pow([b, x]) if matches!(arena.node(*b), Node::Symbol(s) if *s == d) => {
                    let k = arena.as_constant(*x).and_then(Constant::as_integer)?;
                    power += usize::try_from(k).ok()?;
                }
                _ => return None,
            }
        }
        if by_power.len() <= power {
            by_power.resize(power + 1, Vec::new());
        }
        let c = arena.product(&rest);
        by_power[power].push(c);
    }
    let mut out: Vec<ExprId> = by_power
        .into_iter()
        .map(|terms| {
            let s = arena.sum(&terms);
            arena.expand(s)
        })
        .collect();
    while out.len() > 1 && out.last().is_some_and(|&c| arena.is_zero(c)) {
        out.pop();
    }
    Some(out)
}
