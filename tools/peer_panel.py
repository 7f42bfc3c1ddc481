"""The fixed panel of models on which eomgen's integrators are measured against heyoka and
ode_solvers (tools/work_precision_peers.py, tools/heyoka_peer.py). Not used by the product.

Tune on any of them; the goals of docs/performance.md hold on all. Each entry:
- `name`: the key of the tables, the reference file and the JSON lines;
- `model`: a bundled model's name or a model file's path relative to the repository;
- `t_end`: the end of the integration (s), from t = 0;
- `set`: changes to the file's initial state, by coordinate or rate name (`theta_dot`), as
  `eomgen.Model.initial_state` takes them;
- `heyoka`: how heyoka's side is written: `"hand"` (the equations written out in
  tools/heyoka_peer.py), `"lagrangian"` (heyoka's own `lagrangian(L, qs, qdots)` of the
  file's `T − V`, as a heyoka user would write it), or `None` (heyoka cannot express the
  model: constraints);
- `why`: what the model exercises.
"""

import math
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

PANEL = [
    {"name": "double_pendulum", "model": "double_pendulum", "t_end": 10.0, "set": {},
     "heyoka": "hand", "why": "HW19, the model the Taylor method was tuned on: sin, cos, a 2 × 2 mass matrix"},
    {"name": "figure_eight", "model": "figure_eight", "t_end": 63.2591398, "set": {},
     "heyoka": "hand", "why": "HW7, three bodies over 10 periods: r⁻³ (powers, square roots, divisions)"},
    {"name": "heavy_top", "model": "heavy_top", "t_end": 2.0, "set": {"theta_dot": 5.0},
     "heyoka": "lagrangian", "why": "a 3-D body in Euler angles, started off its steady precession"},
    {"name": "kepler_e09", "model": "tools/panel/kepler_e09.yaml", "t_end": 20.0 * math.pi, "set": {},
     "heyoka": "lagrangian", "why": "a Kepler orbit at e = 0.9 over 10 periods, from a model file: r⁻³ at a close periapsis"},
    # Thrown rather than released at rest: from rest with every bar horizontal the series
    # holds only every fourth power of t, and heyoka's step rule, which reads the last two
    # orders, sees zeros there at orders 8, 12, ... (tools/heyoka_peer.py, `first_step`).
    {"name": "five_link_chain", "model": "tools/panel/five_link_chain.yaml", "t_end": 5.0,
     "set": {"theta1_dot": 1.0}, "heyoka": "lagrangian",
     "why": "`eomgen new n-link-pendulum 5` thrown from horizontal: a dense 5 × 5 mass matrix"},
    {"name": "whipple_bicycle", "model": "whipple_bicycle", "t_end": 5.0, "set": {},
     "heyoka": None, "why": "the benchmark bicycle's lean and steer: 3-D bodies, rolling (nonholonomic) constraints"},
]


def entry(name):
    """The panel entry called `name`."""
    for e in PANEL:
        if e["name"] == name:
            return e
    raise KeyError(f"no panel model `{name}` (valid: {', '.join(e['name'] for e in PANEL)})")


def model_argument(e):
    """What eomgen's loaders take for entry `e`: the bundled name, or the file's absolute path."""
    model = e["model"]
    return str(ROOT / model) if model.endswith(".yaml") else model


def set_argument(e):
    """Entry `e`'s initial-state changes as the Rust program's `--set` takes them
    (`theta_dot=5.0`, comma-separated), or None."""
    if not e["set"]:
        return None
    return ",".join(f"{k}={float(v)!r}" for k, v in e["set"].items())
