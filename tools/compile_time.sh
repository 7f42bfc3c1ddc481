#!/usr/bin/env bash
# Compile time of the code eomgen generates for `eomgen new n-link-pendulum N` (issue 4).
# Not used by the product.
#
# For each N it builds a throwaway crate that depends on this workspace's `eomgen`, three
# ways, each with `cargo build --release` (rustc -O, opt-level 3) after its dependencies are
# built, and prints the wall time of each:
#
#   empty     an empty lib.rs: cargo's own overhead, the baseline;
#   generated the code `model!` expands to, printed beforehand by
#             `cargo run -p eomgen-symbolic --example generate` and `include!`d: rustc alone;
#   macro     `eomgen::model!("chain.yaml")`: the derivation and code generation in the proc
#             macro, then rustc on its expansion (what a user pays).
#
# Each variant also has a plain `pub fn exercise` that calls every generated function: they
# are `#[inline]`, so without a caller rustc would only type-check them and leave LLVM's work
# to the crate that simulates. generated − empty is rustc's share and macro − generated the
# proc macro's; which one dominates says where compile time goes. The probe crate sets
# `[profile.release.build-override] opt-level = 3` as this workspace does, so the proc macro
# runs optimized.
#
# Run: tools/compile_time.sh [N ...]      (default: 10 30; builds in CARGO_TARGET_DIR if set,
# else the workspace's target/ and, for the probe, a temporary directory)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
sizes=("$@")
if [ ${#sizes[@]} -eq 0 ]; then
    sizes=(10 30)
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cargo build -q --release --manifest-path "$root/Cargo.toml" --bin eomgen
cargo build -q --release --manifest-path "$root/Cargo.toml" -p eomgen-symbolic --example generate
target=${CARGO_TARGET_DIR:-$root/target}
probe_target=${CARGO_TARGET_DIR:-$work/target}
eomgen="$target/release/eomgen"
generate="$target/release/examples/generate"

mkdir -p "$work/probe/src"
cat > "$work/probe/Cargo.toml" <<EOF
[package]
name = "compile-time-probe"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
eomgen = { path = "$root" }

[profile.release.build-override]
opt-level = 3

[workspace]
EOF

# Seconds taken by `cargo build --release` of the probe's lib.rs as is: the best of three
# (other processes on the machine only ever add time).
build() {
    local best="" start end
    for _ in 1 2 3; do
        touch "$work/probe/src/lib.rs"
        start=$(date +%s.%N)
        CARGO_TARGET_DIR="$probe_target" cargo build -q --release \
            --manifest-path "$work/probe/Cargo.toml"
        end=$(date +%s.%N)
        best=$(echo "$start $end $best" | awk '{ t = $2 - $1; if ($3 != "" && $3 < t) t = $3; printf "%.2f", t }')
    done
    echo "$best"
}

: > "$work/probe/src/lib.rs"
echo "building the probe's dependencies (not timed)..." >&2
build > /dev/null
empty=$(build)

for n in "${sizes[@]}"; do
    "$eomgen" new n-link-pendulum "$n" > "$work/probe/src/chain.yaml"
    "$generate" "$work/probe/src/chain.yaml" > "$work/generated.rs" 2> "$work/generate.log"
    bytes=$(wc -c < "$work/generated.rs")

    cat > "$work/exercise.rs" <<EOF
use eomgen::MechanicalSystem;
type V = eomgen::__private::nalgebra::SVector<f64, $n>;
/// Calls every generated function, so that rustc optimizes and emits their code here.
pub fn exercise(q: &V, qdot: &V, a: &V) -> f64 {
    let s = NLinkPendulum$n::default();
    let (m, f) = s.mass_matrix_and_forcing(q, qdot, 0.0);
    m.sum() + f.sum()
        + s.mass_matrix(q, 0.0).sum()
        + s.forcing(q, qdot, 0.0).sum()
        + s.forcing_jacobian_q(q, qdot, 0.0).sum()
        + s.forcing_jacobian_qdot(q, qdot, 0.0).sum()
        + s.mass_matrix_product_jacobian(q, 0.0, a).sum()
        + s.kinetic_energy(q, qdot, 0.0)
        + s.potential_energy(q, 0.0)
}
EOF
    { echo 'include!("../../generated.rs");'; cat "$work/exercise.rs"; } > "$work/probe/src/lib.rs"
    generated=$(build)
    { echo 'eomgen::model!("chain.yaml");'; cat "$work/exercise.rs"; } > "$work/probe/src/lib.rs"
    macro=$(build)

    echo "n=$n: $(tr '\n' ';' < "$work/generate.log" | sed 's/;$//'); $bytes bytes of code"
    echo "  release build: empty $empty s, generated $generated s, macro $macro s" \
        "(rustc on the code ≈ $(echo "$generated $empty" | awk '{ printf "%.2f", $1 - $2 }') s," \
        "proc macro ≈ $(echo "$macro $generated" | awk '{ printf "%.2f", $1 - $2 }') s)"
done
