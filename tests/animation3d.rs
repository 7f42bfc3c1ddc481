//! The 3-D view's bodies (issue 53, item 5): the orientations the animation composes from the
//! model description's frames against the points the model itself places in those frames, the
//! solids of `draw: shapes:`, and the default box of a body's inertia against the moments it
//! must have.

use eomgen::ModelInfo;
use eomgen::animation::pose::{Poses, Solid};
use eomgen_symbolic::model::parser::eval_expr;

/// The bundled 3-D models and the fixtures whose frames are oblique, Euler parameters or
/// driven.
const MODELS: [&str; 11] = [
    "free_rigid_body",
    "furuta_pendulum",
    "heavy_top",
    "rolling_disc",
    "whipple_bicycle",
    "tests/fixtures/free_rigid_body_quaternion.yaml",
    "tests/fixtures/heavy_top_quaternion.yaml",
    "tests/fixtures/oblique_hinge_body.yaml",
    "tests/fixtures/sleeping_top.yaml",
    "tests/fixtures/spun_hoop.yaml",
    "tests/fixtures/damped_spinning_body.yaml",
];

/// The model and its file's text.
fn load(name: &str) -> (Box<dyn ModelInfo>, String, String) {
    if let Some(entry) = eomgen::models::find(name) {
        return (
            (entry.make)(),
            entry.source().to_string(),
            format!("{name}.yaml"),
        );
    }
    let path = format!("{}/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("fixture");
    let model = eomgen::ModelSource::open(&path)
        .expect("fixture loads")
        .instantiate();
    (model, text, path)
}

/// A point written `{ from: O, F: [a, b, c], … }` must sit at `r_O + Σ R_F [a, b, c]`, with
/// the model's own point positions (compiled from the symbolic frames) on the left and the
/// animation's numerically composed `R_F` on the right: at 6 random configurations and a
/// nonzero `t`, within 1e-12 of the model's size, on every model with 3-D bodies. Every
/// orientation is also a rotation (`RᵀR = I`, `det R = 1` within 1e-13).
#[test]
fn orientations_place_the_points_written_in_the_frames() {
    let mut checked_frames = 0;
    for name in MODELS {
        let (model, text, path) = load(name);
        let file = eomgen_symbolic::model::load(&path, &text).expect("the file loads");
        let poses = Poses::of(model.as_ref()).expect("the description's frames parse");
        let d = model.description();
        let n = d.num_dofs();
        let parameters = eomgen::expressions::parameter_lookup(model.as_ref());
        let mut seed = 0x2545_f491_u64;
        let mut used = std::collections::BTreeSet::new();
        for trial in 0..6 {
            let q: Vec<f64> = (0..n)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.0
                })
                .collect();
            let t = 0.37 * trial as f64;
            let mut y = q.clone();
            y.resize(2 * n, 0.0);
            let positions = model.point_positions(t, &y);
            let scale = positions
                .iter()
                .flatten()
                .fold(1e-3_f64, |m, v| m.max(v.abs()));
            let frames = poses
                .frame_orientations(model.as_ref(), t, &q)
                .expect("orientations");
            for (frame, r) in &frames {
                let error = (r.transpose() * r - nalgebra::Matrix3::identity())
                    .abs()
                    .max();
                assert!(
                    error < 1e-13 && (r.determinant() - 1.0).abs() < 1e-13,
                    "{name}: {frame} is no rotation"
                );
            }
            let lookup = |s: &str| -> Option<f64> {
                if s == "t" {
                    return Some(t);
                }
                d.coordinate_index(s)
                    .map(|i| q[i])
                    .or_else(|| parameters(s))
            };
            for p in &file.points {
                let Some(relative) = &p.relative else {
                    continue;
                };
                let origin = match &relative.from {
                    Some(o) => positions[d.point_index(&o.value).expect("point")],
                    None => [0.0; 3],
                };
                let mut expected = nalgebra::Vector3::from(origin);
                let mut complete = true;
                for (frame, components) in &relative.vectors {
                    let v: Vec<f64> = (components.iter())
                        .map(|e| eval_expr(e, &lookup).expect("component"))
                        .collect();
                    let v = nalgebra::Vector3::new(v[0], v[1], v[2]);
                    if frame.value == "N" {
                        expected += v;
                    } else if let Some((_, r)) = frames.iter().find(|(f, _)| *f == frame.value) {
                        expected += r * v;
                        used.insert(frame.value.clone());
                    } else {
                        complete = false;
                    }
                }
                if !complete {
                    continue;
                }
                let actual = positions[d.point_index(&p.name.value).expect("point")];
                for k in 0..3 {
                    assert!(
                        (actual[k] - expected[k]).abs() <= 1e-12 * scale,
                        "{name}: point {} component {k}: model {} against the composed frames {}",
                        p.name.value,
                        actual[k],
                        expected[k]
                    );
                }
            }
        }
        assert!(
            !used.is_empty(),
            "{name}: no point is written in a frame of a body"
        );
        checked_frames += used.len();
    }
    assert!(checked_frames >= 15, "{checked_frames} frames checked");
}

/// The file's shapes become the solids drawn: the heavy top's disc of its axial moment
/// (`r = √(2 I₃/m)`, a twelfth of it thick) and the Furuta pendulum's rods.
#[test]
fn shapes_from_the_file_are_the_solids_drawn() {
    let (model, _, _) = load("heavy_top");
    let poses = Poses::of(model.as_ref()).expect("poses");
    let radius = (2.0 * 0.01 / 1.0_f64).sqrt();
    assert_eq!(poses.bodies.len(), 1);
    assert_eq!(
        poses.bodies[0].solid,
        Solid::Cylinder {
            radius,
            length: radius / 12.0
        }
    );
    assert!(!poses.bodies[0].from_inertia);
    // The disc's own y axis (the view's cylinders) is the frame's z.
    let q = poses.bodies[0].local_quaternion();
    let turned = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        q[3], q[0], q[1], q[2],
    )) * nalgebra::Vector3::y();
    assert!((turned - nalgebra::Vector3::z()).norm() < 1e-15, "{turned}");
    let (model, _, _) = load("furuta_pendulum");
    let poses = Poses::of(model.as_ref()).expect("poses");
    let solids: Vec<Solid> = poses.bodies.iter().map(|b| b.solid).collect();
    assert_eq!(
        solids,
        [
            Solid::Cylinder {
                radius: 0.005,
                length: 0.2
            },
            Solid::Cylinder {
                radius: 0.005,
                length: 0.3
            }
        ]
    );
}

/// A body without a shape is drawn as the uniform box of its mass and inertia: its axes are
/// the principal axes (the bicycle's frames have products of inertia) and its sides give the
/// principal moments, `Iₖ = m (a_j² + a_k'²)/12`, to 1e-12.
#[test]
fn the_default_box_has_the_bodys_inertia() {
    for (name, body) in [
        ("free_rigid_body", "body"),
        ("whipple_bicycle", "rear_frame"),
        ("whipple_bicycle", "front_frame"),
    ] {
        let (model, _, _) = load(name);
        let poses = Poses::of(model.as_ref()).expect("poses");
        let b = poses.bodies.iter().find(|b| b.name == body).expect("body");
        assert!(b.from_inertia, "{name}: {body}");
        let Solid::Box(sides) = b.solid else {
            panic!("{name}: {body} is {:?}", b.solid)
        };
        let d = model.description();
        let c = d
            .body_centres
            .iter()
            .find(|c| c.body == body)
            .expect("centre");
        let lookup = eomgen::expressions::parameter_lookup(model.as_ref());
        let value = |s: &str| eomgen::expressions::evaluate(s, "inertia", &lookup).expect("value");
        let m = value(&c.mass);
        let i: Vec<f64> = c.inertia.iter().map(|s| value(s)).collect();
        let tensor = nalgebra::Matrix3::new(i[0], i[3], i[5], i[3], i[1], i[4], i[5], i[4], i[2]);
        let q = b.local_quaternion();
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[3], q[0], q[1], q[2],
        ))
        .to_rotation_matrix()
        .into_inner();
        // The tensor in the box's axes is diagonal, and the sides are those of a uniform box
        // of its principal moments, `aₖ² = 6 (I_j + I_k' − I_k)/m` (a side that comes out
        // zero, a plate's, drawn a twentieth of the largest).
        let in_box = r.transpose() * tensor * r;
        let scale = tensor.abs().max();
        let exact = [0, 1, 2].map(|k| {
            let p = |j: usize| in_box[(j % 3, j % 3)];
            (6.0 * (p(k + 1) + p(k + 2) - p(k)) / m).max(0.0).sqrt()
        });
        let largest = exact.iter().copied().fold(0.0, f64::max);
        for k in 0..3 {
            let want = exact[k].max(largest / 20.0);
            assert!(
                (sides[k] - want).abs() < 1e-12 * largest,
                "{name}: {body} side {k}: {} against {want}",
                sides[k]
            );
            for j in 0..3 {
                if j != k {
                    assert!(
                        in_box[(k, j)].abs() < 1e-12 * scale,
                        "{name}: {body} product {k}{j}"
                    );
                }
            }
        }
    }
}
