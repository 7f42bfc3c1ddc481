//! Momentum balance, derived from the kinematics (syllabus lectures 6–7, 11–12, 19; HW19 a,
//! HW20): never from `T`, nor from a `V` of gravity or springs, which enter as forces; a
//! potential the file writes (`potential:`) enters as the forces `−∂V/∂qᵢ`, and written
//! `generalized_forces:` as themselves.
//!
//! For each body, linear momentum balance `m a_G = ΣF` and angular momentum balance about the
//! centre of mass `I_G θ̈ = ΣM_G` are projected on the partial velocities `∂r/∂qᵢ` and partial
//! angular velocities `∂θ/∂qᵢ` (d'Alembert's principle in Kane's form), which eliminates every
//! workless constraint force. Gravity is a force `m g` at each centre of mass, springs are
//! equal and opposite forces along the line of their points. The result `M′ q̈ = F′` must give
//! the same `q̈` as Lagrange's equations.
//!
//! Positions depend on `q` and `t` only (the model checks reject rates in them), so the
//! acceleration of a point splits exactly into a part linear in `q̈` and the rest:
//!
//! ```text
//! v = Σⱼ (∂r/∂qⱼ) q̇ⱼ + ∂r/∂t
//! a = Σⱼ (∂r/∂qⱼ) q̈ⱼ + a₀,   a₀ = Σⱼ (∂v/∂qⱼ) q̇ⱼ + ∂v/∂t
//! ```
//!
//! and `M` and `F` are assembled directly, with no differentiation by `q̈` and no
//! substitution `q̈ = 0`:
//!
//! ```text
//! Mᵢⱼ = Σ_bodies m (∂r/∂qᵢ)·(∂r/∂qⱼ) + I (∂θ/∂qᵢ)(∂θ/∂qⱼ)        (i ≤ j, mirrored)
//! Fᵢ  = Σ_bodies (m g − m a₀)·∂r/∂qᵢ − I α₀ ∂θ/∂qᵢ + Σ_loads F·∂r_P/∂qᵢ + τ ∂θ/∂qᵢ
//!       − ∂V_written/∂qᵢ + Q_written,i
//! ```
//!
//! Bodies whose partial velocities for `qᵢ` (and `qⱼ`) are the same expressions, as are those
//! of all the bars below a joint of a chain, are projected together: `(Σ m) vᵢ·vⱼ` and
//! `(Σ m a₀)·vᵢ`, with `Σ m a₀` of a set of bodies built from that of its largest subset
//! already summed. Each entry is then multiplied out where it changes in time (which brings
//! the products of sines and cosines of the angles together into sines and cosines of angle
//! differences, [`crate::expr::ExprArena::expand_time_varying`]) and collected by its
//! time-varying factors ([`crate::expr::ExprArena::collect_time_varying`]), which factors out
//! the sum of the masses below each joint; the entries are kept as assembled instead when
//! that costs fewer operations after CSE. For the `n`-link pendulum this does `O(n²)`
//! symbolic work outside the mass sums, where summing body by body does `O(n³)`.
//!
//! # References
//! T. R. Kane, D. A. Levinson, *Dynamics: Theory and Applications*, McGraw-Hill, 1985, ch. 6
//! (partial velocities, generalized inertia and active forces). R. Featherstone, *Rigid Body
//! Dynamics Algorithms*, Springer, 2008 (the velocity-product acceleration `a₀` of the
//! recursive Newton–Euler algorithm).

use rustc_hash::FxHashMap;

use super::frames::{Vector3, cross, tensor_times};
use super::lower::{BodyInfo, LoadInfo};
use super::{EquationsOfMotion, Formulation, SymbolicModel};
use crate::expr::{ExprArena, ExprId, SymbolId};
use crate::model::elements::{damper, spring};

/// Momentum balance of each body projected on the partial velocities (Kane / d'Alembert).
#[derive(Debug, Clone, Copy, Default)]
pub struct MomentumBalance;

impl MomentumBalance {
    /// Whether the model can be derived by momentum balance: it has bodies, no written
    /// `kinetic:` and no generalized speeds (whose equations are [`super::Kane`]'s) (a written `potential:` enters as the generalized forces `−∂V/∂qᵢ`, written
    /// `generalized_forces:` as themselves).
    pub fn applies_to(model: &SymbolicModel) -> bool {
        !model.kinetic_written && !model.bodies.is_empty() && model.speeds.is_none()
    }
}

/// Partial velocities and velocity-product accelerations of a model's points, each derived
/// once and shared by every body and load at that point.
struct Kinematics<'a> {
    /// Position components per point.
    points: &'a [Vec<ExprId>],
    /// `(q, q̇, q̈)` symbols per coordinate.
    symbols: &'a [[SymbolId; 3]],
    /// The time symbol.
    time: SymbolId,
    /// Per point, the id (into `vectors`) of `∂r/∂qᵢ` per coordinate, `None` where it is
    /// zero.
    partials: Vec<Option<Vec<Option<usize>>>>,
    /// The distinct partial velocities.
    vectors: Vec<Vec<ExprId>>,
    /// Index of `vectors`.
    vector_ids: FxHashMap<Vec<ExprId>, usize>,
    /// Per point, `a₀`.
    accelerations: Vec<Option<Vec<ExprId>>>,
    /// `vᵢ·vⱼ` multiplied out, per pair of partial-velocity ids.
    dots: FxHashMap<(usize, usize), ExprId>,
}

impl<'a> Kinematics<'a> {
    fn new(points: &'a [Vec<ExprId>], symbols: &'a [[SymbolId; 3]], time: SymbolId) -> Self {
        Self {
            points,
            symbols,
            time,
            partials: vec![None; points.len()],
            vectors: Vec::new(),
            vector_ids: FxHashMap::default(),
            accelerations: vec![None; points.len()],
            dots: FxHashMap::default(),
        }
    }

    /// The ids of `∂r/∂qᵢ` of point `p` for every coordinate `i`, `None` where it is zero.
    fn partials(&mut self, arena: &mut ExprArena, p: usize) -> Vec<Option<usize>> {
        if let Some(ids) = &self.partials[p] {
            return ids.clone();
        }
        let ids: Vec<Option<usize>> = self
            .symbols
            .iter()
            .map(|s| {
                let d: Vec<ExprId> = self.points[p]
                    .iter()
                    .map(|c| arena.diff(*c, s[0]))
                    .collect();
                if d.iter().all(|c| arena.is_zero(*c)) {
                    return None;
                }
                let next = self.vectors.len();
                let id = *self.vector_ids.entry(d.clone()).or_insert(next);
                if id == next {
                    self.vectors.push(d);
                }
                Some(id)
            })
            .collect();
        self.partials[p] = Some(ids.clone());
        ids
    }

    /// The partial velocity with id `v`.
    fn vector(&self, v: usize) -> &[ExprId] {
        &self.vectors[v]
    }

    /// The velocity-product acceleration `a₀` of point `p` (its acceleration at `q̈ = 0`).
    fn acceleration(&mut self, arena: &mut ExprArena, p: usize) -> Vec<ExprId> {
        let (points, symbols, time) = (self.points, self.symbols, self.time);
        self.accelerations[p]
            .get_or_insert_with(|| {
                points[p]
                    .iter()
                    .map(|c| {
                        let v = arena.time_derivative(*c);
                        velocity_product(arena, v, symbols, time)
                    })
                    .collect()
            })
            .clone()
    }

    /// `vₐ·v_b` of two partial velocities, multiplied out.
    fn partial_dot(&mut self, arena: &mut ExprArena, a: usize, b: usize) -> ExprId {
        let key = (a.min(b), a.max(b));
        if let Some(&d) = self.dots.get(&key) {
            return d;
        }
        let d = dot_multiplied_out(arena, &self.vectors[a], &self.vectors[b]);
        self.dots.insert(key, d);
        d
    }
}

/// `a·b`, multiplied out where it changes in time (so that products of sines and cosines of
/// two angles meet as the terms of one sum and become functions of their difference), unless
/// a component is nested too deeply to multiply out ([`ExprArena::expands_shallowly`]: a
/// point of a chain of 3-D bodies in relative rotations), when the products are kept.
fn dot_multiplied_out(arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]) -> ExprId {
    if !a.iter().chain(b).all(|&c| arena.expands_shallowly(c)) {
        return dot(arena, a, b);
    }
    let terms: Vec<ExprId> = a
        .iter()
        .zip(b)
        .map(|(x, y)| {
            let p = arena.times(*x, *y);
            arena.expand_time_varying(p)
        })
        .collect();
    arena.sum(&terms)
}

/// `Σⱼ (∂e/∂qⱼ) q̇ⱼ + ∂e/∂t`: the time derivative of `e` (a function of `q`, `q̇`, `t` that
/// is linear in `q̇`) without its `q̈` terms.
fn velocity_product(
    arena: &mut ExprArena,
    e: ExprId,
    symbols: &[[SymbolId; 3]],
    time: SymbolId,
) -> ExprId {
    let mut terms = vec![arena.diff(e, time)];
    for s in symbols {
        let d = arena.diff(e, s[0]);
        if !arena.is_zero(d) {
            let rate = arena.symbol_expr(s[1]);
            terms.push(arena.times(d, rate));
        }
    }
    arena.sum(&terms)
}

/// Sums over sets of bodies (sorted body indices), each computed once: the total mass
/// `Σ m`, and the mass-weighted velocity-product acceleration `Σ m a₀` collected by its
/// time-varying factors.
///
/// The sets are those of the bodies sharing a partial velocity, which for a chain are the
/// bars below each joint: nested sets, so `Σ m a₀` of a set starts from the largest subset
/// already summed (`O(n)` new terms per joint instead of `O(n²)`).
#[derive(Default)]
struct BodySums {
    masses: FxHashMap<Vec<usize>, ExprId>,
    accelerations: Vec<(Vec<usize>, Vec<ExprId>)>,
}

impl BodySums {
    /// `Σ m` over `set`.
    fn mass(&mut self, arena: &mut ExprArena, bodies: &[BodyInfo], set: &[usize]) -> ExprId {
        if let Some(&m) = self.masses.get(set) {
            return m;
        }
        let masses: Vec<ExprId> = set.iter().map(|&b| bodies[b].mass).collect();
        let m = arena.sum(&masses);
        self.masses.insert(set.to_vec(), m);
        m
    }

    /// `Σ m a₀` over `set`, collected by time-varying factors, component by component.
    fn weighted_acceleration(
        &mut self,
        arena: &mut ExprArena,
        kinematics: &mut Kinematics<'_>,
        bodies: &[BodyInfo],
        set: &[usize],
    ) -> Vec<ExprId> {
        if let Some((_, w)) = self.accelerations.iter().find(|(s, _)| s == set) {
            return w.clone();
        }
        let subset = self
            .accelerations
            .iter()
            .filter(|(s, _)| s.len() < set.len() && s.iter().all(|b| set.binary_search(b).is_ok()))
            .max_by_key(|(s, _)| s.len());
        let (mut terms, added): (Vec<Vec<ExprId>>, Vec<usize>) = match subset {
            Some((s, w)) => (
                w.iter().map(|c| vec![*c]).collect(),
                set.iter()
                    .copied()
                    .filter(|b| s.binary_search(b).is_err())
                    .collect(),
            ),
            None => (Vec::new(), set.to_vec()),
        };
        for b in added {
            let a = kinematics.acceleration(arena, bodies[b].com);
            terms.resize(a.len(), Vec::new());
            for (t, c) in terms.iter_mut().zip(a) {
                t.push(arena.times(bodies[b].mass, c));
            }
        }
        let w: Vec<ExprId> = terms
            .iter()
            .map(|t| {
                let s = arena.sum(t);
                let x = arena.expand_time_varying(s);
                arena.collect_time_varying(x)
            })
            .collect();
        self.accelerations.push((set.to_vec(), w.clone()));
        w
    }
}

/// The bodies of `candidates` (in index order) grouped by the key `key(b)` (skipping
/// `None`), groups in order of first appearance, bodies in index order.
fn group_bodies<K: PartialEq>(
    candidates: &[usize],
    key: impl Fn(usize) -> Option<K>,
) -> Vec<(K, Vec<usize>)> {
    let mut groups: Vec<(K, Vec<usize>)> = Vec::new();
    for &b in candidates {
        let Some(k) = key(b) else { continue };
        match groups.iter_mut().find(|(g, _)| *g == k) {
            Some((_, members)) => members.push(b),
            None => groups.push((k, vec![b])),
        }
    }
    groups
}

impl Formulation for MomentumBalance {
    fn name(&self) -> &'static str {
        "momentum"
    }

    /// # Panics
    /// Never; for a model where [`MomentumBalance::applies_to`] is false a written `kinetic:`
    /// is ignored, so callers check it first.
    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let time = model.time_symbol();
        let points: Vec<Vec<ExprId>> = model.points.iter().map(|(_, r)| r.clone()).collect();
        let bodies = model.bodies.clone();
        let loads = model.loads.clone();
        let gravity = model.gravity.clone();
        let (model_potential, written_forces) =
            (model.written_potential, model.written_forces.clone());
        let arena = &mut model.arena;
        let mut kinematics = Kinematics::new(&points, &symbols, time);
        let mut sums = BodySums::default();
        let partials: Vec<Vec<Option<usize>>> = bodies
            .iter()
            .map(|b| kinematics.partials(arena, b.com))
            .collect();

        // Σ m a₀ of every set of bodies that shares a partial velocity, smallest sets first,
        // so that each is built from the largest subset already summed. (In the order of the
        // coordinates, the bars below joint 1 would come first, and with no subset yet
        // summed every set would be summed from scratch: `O(n³)` terms for a chain.)
        // The bodies that move with each coordinate (a non-zero partial velocity), in index
        // order: a pair of coordinates is projected over the shorter of their two lists, so a
        // chain of masses that each move with one coordinate costs `O(n²)`, not
        // `O(n² × bodies)` (2.3 s for 1000 masses).
        let moving: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                (0..bodies.len())
                    .filter(|&b| partials[b][i].is_some())
                    .collect()
            })
            .collect();
        let mut sets: Vec<Vec<usize>> = Vec::new();
        for groups in (0..n).map(|i| group_bodies(&moving[i], |b| partials[b][i])) {
            for (_, set) in groups {
                if !sets.contains(&set) {
                    sets.push(set);
                }
            }
        }
        sets.sort_by_key(Vec::len);
        for set in &sets {
            sums.weighted_acceleration(arena, &mut kinematics, &bodies, set);
        }

        // Terms of Mᵢⱼ (i ≤ j, row-major) and of Fᵢ. Bodies with the same partial velocities
        // (all the bars below a joint) are projected together, as one mass `Σ m` and one
        // `Σ m a₀`: Kane's generalized inertia forces of a chain, by hand.
        let mut mass_terms: Vec<Vec<ExprId>> = vec![Vec::new(); n * n];
        let mut forcing_terms: Vec<Vec<ExprId>> = vec![Vec::new(); n];
        for i in 0..n {
            for j in i..n {
                let shorter = if moving[i].len() <= moving[j].len() {
                    &moving[i]
                } else {
                    &moving[j]
                };
                let groups = group_bodies(shorter, |b| Some((partials[b][i]?, partials[b][j]?)));
                for ((vi, vj), set) in groups {
                    let mass = sums.mass(arena, &bodies, &set);
                    let d = kinematics.partial_dot(arena, vi, vj);
                    mass_terms[i * n + j].push(arena.times(mass, d));
                }
            }
            // (Σ m g − Σ m a₀)·∂r/∂qᵢ
            for (v, set) in group_bodies(&moving[i], |b| partials[b][i]) {
                let r = kinematics.vector(v).to_vec();
                let w = sums.weighted_acceleration(arena, &mut kinematics, &bodies, &set);
                let inertial = dot_multiplied_out(arena, &w, &r);
                forcing_terms[i].push(arena.neg(inertial));
                if let Some(g) = &gravity {
                    let mass = sums.mass(arena, &bodies, &set);
                    let weight = dot_multiplied_out(arena, g, &r);
                    forcing_terms[i].push(arena.times(mass, weight));
                }
            }
        }
        let mut terms = Terms {
            n,
            mass: mass_terms,
            forcing: forcing_terms,
        };
        terms.rotations(arena, &bodies, (&symbols, time));
        terms.spatial_bodies(arena, &bodies, (&symbols, time));
        terms.written(arena, &symbols, (model_potential, &written_forces));
        terms.loads(arena, &mut kinematics, (&points, &bodies, &loads), &symbols);
        terms.equations(arena)
    }
}

/// The terms of `M` (`n × n`, `i ≤ j`, row-major) and of `F` as the momentum balance adds them:
/// the translations' (in [`MomentumBalance::derive`]), then each kind of contribution below, in
/// this order.
struct Terms {
    n: usize,
    mass: Vec<Vec<ExprId>>,
    forcing: Vec<Vec<ExprId>>,
}

impl Terms {
    /// Planar rigid bodies' rotations: `Mᵢⱼ += I ∂θ/∂qᵢ ∂θ/∂qⱼ`, `Fᵢ −= I α₀ ∂θ/∂qᵢ`.
    fn rotations(
        &mut self,
        arena: &mut ExprArena,
        bodies: &[BodyInfo],
        (symbols, time): (&[[SymbolId; 3]], SymbolId),
    ) {
        let n = self.n;
        for body in bodies {
            if let Some((inertia, angle)) = body.rotation {
                let rates: Vec<ExprId> = symbols.iter().map(|s| arena.diff(angle, s[0])).collect();
                let omega = arena.time_derivative(angle);
                let alpha = velocity_product(arena, omega, symbols, time);
                for i in 0..n {
                    if arena.is_zero(rates[i]) {
                        continue;
                    }
                    for j in i..n {
                        if !arena.is_zero(rates[j]) {
                            self.mass[i * n + j]
                                .push(arena.product(&[inertia, rates[i], rates[j]]));
                        }
                    }
                    let torque = arena.product(&[inertia, alpha, rates[i]]);
                    self.forcing[i].push(arena.neg(torque));
                }
            }
        }
    }

    /// 3-D bodies: Euler's equations projected on the partial angular velocities.
    fn spatial_bodies(
        &mut self,
        arena: &mut ExprArena,
        bodies: &[BodyInfo],
        (symbols, time): (&[[SymbolId; 3]], SymbolId),
    ) {
        let n = self.n;
        // 3-D bodies: Euler's equations `I_G α + ω × I_G ω` projected on the partial angular
        // velocities `Wᵢ = ∂ω/∂q̇ᵢ`, all in the body frame's components (where `I_G` is
        // constant and `α` is the time derivative of ω's components). With `α = Σ Wⱼ q̈ⱼ +
        // α₀`: `Mᵢⱼ += Wᵢ·I Wⱼ`, `Fᵢ −= Wᵢ·(I α₀ + ω × I ω)`.
        for body in bodies {
            let Some(spatial) = &body.spatial else {
                continue;
            };
            let w = spatial.angular_velocity;
            let partial: Vec<Option<Vector3>> = symbols
                .iter()
                .map(|s| {
                    let p = w.map(|c| arena.diff(c, s[1]));
                    (!p.iter().all(|c| arena.is_zero(*c))).then_some(p)
                })
                .collect();
            let alpha = w.map(|c| velocity_product(arena, c, symbols, time));
            let i_alpha = tensor_times(arena, &spatial.inertia, &alpha);
            let i_w = tensor_times(arena, &spatial.inertia, &w);
            let gyroscopic = cross(arena, &w, &i_w);
            let euler: Vec<ExprId> = i_alpha
                .iter()
                .zip(&gyroscopic)
                .map(|(a, b)| arena.plus(*a, *b))
                .collect();
            for i in 0..n {
                let Some(wi) = &partial[i] else { continue };
                let i_wi = tensor_times(arena, &spatial.inertia, wi);
                for (j, wj) in partial.iter().enumerate().skip(i) {
                    if let Some(wj) = wj {
                        self.mass[i * n + j].push(dot_multiplied_out(arena, &i_wi, wj));
                    }
                }
                let inertial = dot_multiplied_out(arena, &euler, wi);
                self.forcing[i].push(arena.neg(inertial));
            }
        }
    }

    /// The file's written potential `V` and generalized forces `Q`: `Fᵢ += −∂V/∂qᵢ + Qᵢ`.
    fn written(
        &mut self,
        arena: &mut ExprArena,
        symbols: &[[SymbolId; 3]],
        (potential, written): (ExprId, &[ExprId]),
    ) {
        // The file's written potential and generalized forces: `−∂V/∂qᵢ + Qᵢ`.
        for (i, s) in symbols.iter().enumerate() {
            let dv = arena.diff(potential, s[0]);
            if !arena.is_zero(dv) {
                self.forcing[i].push(arena.neg(dv));
            }
            if !arena.is_zero(written[i]) {
                self.forcing[i].push(written[i]);
            }
        }
    }

    /// `M` (symmetric, each entry the sum of its terms) and `F`, as given or multiplied out and
    /// collected, whichever is cheaper ([`cheaper_of_raw_and_collected`]).
    fn equations(self, arena: &mut ExprArena) -> EquationsOfMotion {
        let n = self.n;
        let mut mass_matrix = vec![arena.int(0); n * n];
        for i in 0..n {
            for j in i..n {
                let m = arena.sum(&self.mass[i * n + j]);
                mass_matrix[i * n + j] = m;
                mass_matrix[j * n + i] = m;
            }
        }
        let forcing: Vec<ExprId> = self.forcing.iter().map(|t| arena.sum(t)).collect();
        let (mass_matrix, forcing) = cheaper_of_raw_and_collected(arena, mass_matrix, forcing);
        EquationsOfMotion {
            num_dofs: n,
            mass_matrix,
            forcing,
        }
    }

    /// The loads (springs, dampers, forces, torques, interactions), each as forces at points
    /// and torques, projected on the partial velocities.
    fn loads(
        &mut self,
        arena: &mut ExprArena,
        kinematics: &mut Kinematics,
        (points, bodies, loads): (&[Vec<ExprId>], &[BodyInfo], &[LoadInfo]),
        symbols: &[[SymbolId; 3]],
    ) {
        for load in loads {
            // Each load as forces at points (and torques), projected on partial velocities.
            let LoadForces { forces, torque } =
                if let LoadInfo::SpatialTorque { body, vector } = load {
                    // τ·∂ω/∂q̇ᵢ, both in the body frame's components.
                    if let Some(spatial) = &bodies[*body].spatial {
                        for (i, s) in symbols.iter().enumerate() {
                            let partial = spatial.angular_velocity.map(|c| arena.diff(c, s[1]));
                            let power = dot(arena, vector, &partial);
                            if !arena.is_zero(power) {
                                self.forcing[i].push(power);
                            }
                        }
                    }
                    LoadForces::default()
                } else {
                    load_forces(arena, points, load)
                };
            for (point, f) in &forces {
                for (i, r) in kinematics.partials(arena, *point).into_iter().enumerate() {
                    if let Some(r) = r {
                        self.forcing[i].push(dot(arena, f, kinematics.vector(r)));
                    }
                }
            }
            if let Some((angle, value)) = torque {
                for (i, s) in symbols.iter().enumerate() {
                    let rate = arena.diff(angle, s[0]);
                    if !arena.is_zero(rate) {
                        self.forcing[i].push(arena.times(value, rate));
                    }
                }
            }
        }
    }
}

/// `(M, F)` as given or multiplied out and collected entry by entry
/// ([`ExprArena::collect_time_varying`]), whichever costs fewer operations after CSE.
fn cheaper_of_raw_and_collected(
    arena: &mut ExprArena,
    mass_matrix: Vec<ExprId>,
    forcing: Vec<ExprId>,
) -> (Vec<ExprId>, Vec<ExprId>) {
    let mut compact = |e: ExprId| {
        let x = arena.expand_time_varying(e);
        arena.collect_time_varying(x)
    };
    let collected_mass: Vec<ExprId> = mass_matrix.iter().map(|&m| compact(m)).collect();
    let collected_forcing: Vec<ExprId> = forcing.iter().map(|&f| compact(f)).collect();
    let cost = |arena: &ExprArena, m: &[ExprId], f: &[ExprId]| {
        let roots: Vec<ExprId> = m.iter().chain(f).copied().collect();
        crate::expr::cse::operation_count(arena, &roots)
    };
    if cost(arena, &collected_mass, &collected_forcing) <= cost(arena, &mass_matrix, &forcing) {
        (collected_mass, collected_forcing)
    } else {
        (mass_matrix, forcing)
    }
}

/// `a·b`.
pub(crate) fn dot(arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]) -> ExprId {
    let t: Vec<ExprId> = a.iter().zip(b).map(|(x, y)| arena.times(*x, *y)).collect();
    arena.sum(&t)
}

/// `d = r_A − r_B` for points `a` and `b`.
fn separation(arena: &mut ExprArena, points: &[Vec<ExprId>], a: usize, b: usize) -> Vec<ExprId> {
    points[a]
        .iter()
        .zip(&points[b])
        .map(|(x, y)| arena.minus(*x, *y))
        .collect()
}

/// A planar or point load as what it does: forces at points and a torque on a body's angle.
#[derive(Debug, Clone, Default)]
pub(crate) struct LoadForces {
    /// `(point, force vector)` pairs (N): a spring or damper gives an equal and opposite pair.
    pub(crate) forces: Vec<(usize, Vec<ExprId>)>,
    /// `(angle, torque)`: a planar torque (N·m) on the body whose angle expression is `angle`.
    pub(crate) torque: Option<(ExprId, ExprId)>,
}

/// The forces at points and the planar torque of `load` ([`LoadInfo`]), shared by the
/// momentum balance (projected on partial velocities), the power route `P = Ė_K` (dotted
/// with velocities) and linear momentum balances (summed along a direction). A spring pulls
/// its end `A` by `F_A = −k (|d| − ℓ₀) d/|d|`, `d = r_A − r_B`, a damper by
/// `F_A = −c (ḋ·d) d/(d·d)`, each with `F_B = −F_A`. A 3-D torque
/// ([`LoadInfo::SpatialTorque`]) acts through the body's angular velocity and is not a force
/// or a planar torque: it gives nothing here.
pub(crate) fn load_forces(
    arena: &mut ExprArena,
    points: &[Vec<ExprId>],
    load: &LoadInfo,
) -> LoadForces {
    let mut out = LoadForces::default();
    match load {
        LoadInfo::SpatialTorque { .. } => {}
        LoadInfo::Force { point, vector } => out.forces.push((*point, vector.clone())),
        LoadInfo::Torque { angle, value, .. } => out.torque = Some((*angle, *value)),
        LoadInfo::Spring {
            between: [pa, pb],
            stiffness,
            rest_length,
        } => {
            let d = separation(arena, points, *pa, *pb);
            let scale = spring::force_scale(arena, &d, *stiffness, *rest_length);
            out.forces
                .extend(equal_and_opposite(arena, *pa, *pb, &d, scale));
        }
        LoadInfo::Damper {
            between: [pa, pb],
            coefficient,
        } => {
            let d = separation(arena, points, *pa, *pb);
            let rate_of: Vec<ExprId> = d.iter().map(|c| arena.time_derivative(*c)).collect();
            let scale = damper::force_scale(arena, (&d, &rate_of), *coefficient);
            out.forces
                .extend(equal_and_opposite(arena, *pa, *pb, &d, scale));
        }
    }
    out
}

/// The pair of forces `s·d` on `a` and `−s·d` on `b` (a spring or damper along the line).
fn equal_and_opposite(
    arena: &mut ExprArena,
    a: usize,
    b: usize,
    d: &[ExprId],
    scale: ExprId,
) -> [(usize, Vec<ExprId>); 2] {
    let fa: Vec<ExprId> = d.iter().map(|c| arena.times(scale, *c)).collect();
    let fb: Vec<ExprId> = fa.iter().map(|c| arena.neg(*c)).collect();
    [(a, fa), (b, fb)]
}

/// Equations `Rₖ(q, q̇, q̈, t) = 0`, each linear in `q̈`, as `M′ q̈ = F′`:
/// `M′ₖⱼ = ∂Rₖ/∂q̈ⱼ`, `F′ₖ = −Rₖ(q̈ = 0)`, multiplied out if that is cheaper after CSE.
pub(crate) fn linear_in_accelerations(
    arena: &mut crate::expr::ExprArena,
    residual: &[Vec<ExprId>],
    symbols: &[[crate::expr::SymbolId; 3]],
) -> EquationsOfMotion {
    let zero = arena.int(0);
    let at_rest: FxHashMap<_, _> = symbols.iter().map(|s| (s[2], zero)).collect();
    let mut mass_matrix = Vec::with_capacity(residual.len() * symbols.len());
    let mut forcing = Vec::with_capacity(residual.len());
    for terms in residual {
        let r = arena.sum(terms);
        for s in symbols {
            mass_matrix.push(arena.diff(r, s[2]));
        }
        let r0 = arena.substitute(r, &at_rest);
        forcing.push(arena.neg(r0));
    }
    let (mass_matrix, forcing) = super::cheaper_of_raw_and_expanded(arena, mass_matrix, forcing);
    EquationsOfMotion {
        num_dofs: symbols.len(),
        mass_matrix,
        forcing,
    }
}

#[cfg(test)]
mod choice_tests {
    use super::*;
    use crate::expr::cse::operation_count;

    /// `(x + 1)² − x² − 2x` collects to 1 and is kept collected; `(x + 1)⁶` is kept as
    /// given, its expansion costing more. Either way the kept form costs no more than the
    /// other. (On a tie the collected form is kept; the raw one would be as good.)
    #[test]
    fn the_cheaper_of_the_raw_and_the_collected_form_is_kept() {
        let (mut a, x, x1, cancelling) = super::super::tests::cancelling_square();
        let (one, six) = (a.int(1), a.int(6));
        let (m, _) = cheaper_of_raw_and_collected(&mut a, vec![cancelling], vec![x]);
        let d = a.minus(m[0], one);
        assert!(a.is_zero(d), "{m:?}");
        let sixth = a.pow(x1, six);
        let expanded = a.expand_time_varying(sixth);
        let collected = a.collect_time_varying(expanded);
        let (m, _) = cheaper_of_raw_and_collected(&mut a, vec![sixth], vec![x]);
        let kept = operation_count(&a, &m);
        assert!(kept <= operation_count(&a, &[sixth]));
        assert!(kept <= operation_count(&a, &[collected]));
    }
}
