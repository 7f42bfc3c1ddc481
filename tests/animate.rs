//! `eomgen animate` and `eomgen modes --animate` end to end: the page is self-contained and
//! byte-identical across runs, its frames are the mechanism's geometry at independently
//! computed states (closed-form kinematics of the triple pendulum and the four-bar on
//! `simulate --t-out` states), its energies are the closed-form energy, and the GIF decodes.

use crate::common;
use common::{eomgen, eomgen_ok};

use serde_json::Value;
use std::f64::consts::TAU;

/// A file in the tests' scratch directory, removed if an earlier run left it (so that a test
/// never reads a file it did not write).
fn scratch(name: &str) -> String {
    let path = format!("{}/animate-{name}", env!("CARGO_TARGET_TMPDIR"));
    let _ = std::fs::remove_file(&path);
    path
}

/// Runs `eomgen args`, asserting success, and returns stdout.
fn run_ok(args: &[&str]) -> String {
    String::from_utf8_lossy(&eomgen_ok(args).stdout).into_owned()
}

/// The page's `const DATA = …;` as JSON.
fn data_of(html: &str) -> Value {
    let start = html.find("const DATA = ").expect("DATA in the page") + "const DATA = ".len();
    let end = start + html[start..].find(";\n</script>").expect("end of DATA");
    serde_json::from_str(&html[start..end]).expect("DATA is JSON")
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// Frame `k`'s points as `(x, y)`, in the order of `names`.
fn frame(clip: &Value, k: usize) -> Vec<(f64, f64)> {
    numbers(&clip["xy"][k])
        .chunks(2)
        .map(|p| (p[0], p[1]))
        .collect()
}

/// The page's drawn points' names, in the frames' order.
fn names(data: &Value) -> Vec<&str> {
    data["names"]
        .as_array()
        .expect("names")
        .iter()
        .map(|n| n.as_str().expect("name"))
        .collect()
}

/// Frame `k`'s positions of the points named `wanted` (by the page's `names`).
fn named(data: &Value, clip: &Value, k: usize, wanted: &[&str]) -> Vec<(f64, f64)> {
    let names = names(data);
    let all = frame(clip, k);
    wanted
        .iter()
        .map(|w| all[names.iter().position(|n| n == w).expect("a drawn point")])
        .collect()
}

fn distance(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// The triple pendulum (m = 1 kg, l = 1 m, g = 10 m/s², uniform bars, absolute angles from
/// +x): hinge points `P0…P3` and `T + V` in closed form (HW39), independent of the generated
/// code: `T = Σ ½ m |v_G|² + ½ (m l²/12) θ̇²`, `V = m g Σ y_G`.
fn triple_pendulum(q: &[f64], qdot: &[f64]) -> (Vec<(f64, f64)>, f64) {
    let (m, l, g) = (1.0, 1.0, 10.0);
    let mut hinge = (0.0, 0.0);
    let mut hinge_velocity = (0.0, 0.0);
    let mut points = vec![hinge];
    let mut energy = 0.0;
    for (theta, omega) in q.iter().zip(qdot) {
        let (s, c) = theta.sin_cos();
        let centre = (hinge.0 + 0.5 * l * c, hinge.1 + 0.5 * l * s);
        let centre_velocity = (
            hinge_velocity.0 - 0.5 * l * s * omega,
            hinge_velocity.1 + 0.5 * l * c * omega,
        );
        energy += 0.5 * m * (centre_velocity.0.powi(2) + centre_velocity.1.powi(2))
            + 0.5 * (m * l * l / 12.0) * omega * omega
            + m * g * centre.1;
        hinge = (hinge.0 + l * c, hinge.1 + l * s);
        hinge_velocity = (
            hinge_velocity.0 - l * s * omega,
            hinge_velocity.1 + l * c * omega,
        );
        points.push(hinge);
    }
    (points, energy)
}

/// The page holds no reference to anything outside it, and two runs write the same bytes.
#[test]
fn page_is_self_contained_and_deterministic() {
    let (a, b) = (scratch("det-a.html"), scratch("det-b.html"));
    for path in [&a, &b] {
        run_ok(&["animate", "triple_pendulum", "--t-end", "2", "-o", path]);
    }
    let (html_a, html_b) = (
        std::fs::read(&a).expect("page a"),
        std::fs::read(&b).expect("page b"),
    );
    assert!(html_a == html_b, "two runs wrote different pages");
    let html = String::from_utf8(html_a).expect("UTF-8");
    for outside in [
        "http://", "https://", "<link", " src=", "url(", "@import", "//cdn",
    ] {
        assert!(
            !html.contains(outside),
            "the page refers outside: `{outside}`"
        );
    }
    assert!(html.contains("id=\"play\"") && html.contains("id=\"scrub\""));
    assert!(html.contains("id=\"speed\"") && html.contains("id=\"errors\""));
    // 10 s at 30 fps is well under the half megabyte the page may weigh.
    run_ok(&["animate", "triple_pendulum", "-o", &a]);
    let size = std::fs::metadata(&a).expect("page").len();
    assert!(size < 500_000, "{size} bytes");
}

/// A bouncing ball's page lists its impacts: the times and energies of `simulate --json`'s
/// transitions (to the page's rounding, 1e-10 s), in order; and its energy drift is measured
/// on `E` plus the energy lost (every frame's within 1e-9, where `E` alone falls by most of
/// `E₀` through the impacts).
#[test]
fn a_bouncing_balls_page_marks_its_impacts() {
    let page = scratch("ball.html");
    run_ok(&["animate", "bouncing_ball", "--t-end", "5", "-o", &page]);
    let data = data_of(&std::fs::read_to_string(&page).expect("page"));
    let clip = &data["clips"][0];
    let events = clip["ev"].as_array().expect("transitions in the page");
    let json: Value = serde_json::from_str(&run_ok(&[
        "simulate",
        "bouncing_ball",
        "--t-end",
        "5",
        "--json",
    ]))
    .expect("JSON");
    let transitions = json["transitions"].as_array().expect("transitions");
    assert_eq!(events.len(), transitions.len());
    assert!(events.len() > 20, "{} transitions", events.len());
    for (e, tr) in events.iter().zip(transitions) {
        let t = tr["t"].as_f64().unwrap();
        assert!(
            (e[0].as_f64().unwrap() - t).abs() < 1e-10,
            "{e:?} against {tr:?}"
        );
        assert!(
            e[1].as_str().unwrap().starts_with("impact at `floor`"),
            "{e:?}"
        );
    }
    // Each transition's frame is the first after its sample: its time at or after the
    // transition's (frames are at k/fps).
    let times = numbers(&clip["t"]);
    for e in events {
        let frame = e[2].as_u64().unwrap() as usize;
        assert!(times[frame] >= e[0].as_f64().unwrap() - 1e-12, "{e:?}");
        assert!(
            frame == 0 || times[frame - 1] <= e[0].as_f64().unwrap() + 1e-12,
            "{e:?}"
        );
    }
    let drift = numbers(&clip["de"]);
    assert!(drift.iter().all(|d| d.abs() < 1e-9), "{drift:?}");
    let energy = numbers(&clip["e"]);
    assert!(energy.last().unwrap() < &(0.2 * energy[0]), "{energy:?}");
}

/// Every frame of the triple pendulum keeps its bars 1 m long (the positions are rounded to
/// 1e-11 of the picture, so 1e-9 has a margin of 100), the frames are at k / fps, and at
/// three frames the points and the energy agree with the closed-form geometry and energy of
/// the state `simulate --t-out` computes at the same time (dense output of the same method
/// and tolerances: the same numbers to rounding; 1e-9 m and 1e-9 J).
#[test]
fn triple_pendulum_frames_are_the_mechanism_at_simulated_states() {
    let path = scratch("triple.html");
    let printed = run_ok(&[
        "animate",
        "triple_pendulum",
        "--t-end",
        "4",
        "--fps",
        "25",
        "-o",
        &path,
    ]);
    assert!(printed.contains("101 frames"), "{printed}");
    let data = data_of(&std::fs::read_to_string(&path).expect("page"));
    // The hinges and the bars' centres of mass (rings: the model's bodies), in file order.
    assert_eq!(
        data["names"],
        serde_json::json!(["P0", "G1", "P1", "G2", "P2", "G3", "P3"])
    );
    assert_eq!(data["lines"], serde_json::json!([[0, 2], [2, 4], [4, 6]]));
    assert_eq!(data["traces"], serde_json::json!([6]));
    assert_eq!(data["centres"], serde_json::json!([1, 3, 5]));
    let clip = &data["clips"][0];
    let t = numbers(&clip["t"]);
    assert_eq!(t.len(), 101);
    for (k, tk) in t.iter().enumerate() {
        assert_eq!(*tk, k as f64 / 25.0, "frame {k} time");
        let p = named(&data, clip, k, &["P0", "P1", "P2", "P3"]);
        let g = named(&data, clip, k, &["G1", "G2", "G3"]);
        assert!(distance(p[0], (0.0, 0.0)) < 1e-9, "frame {k}: pivot moved");
        for i in 1..4 {
            let length = distance(p[i - 1], p[i]);
            assert!(
                (length - 1.0).abs() < 1e-9,
                "frame {k}: bar {i} is {length} m"
            );
            // A uniform bar's centre of mass is its midpoint.
            let middle = ((p[i - 1].0 + p[i].0) / 2.0, (p[i - 1].1 + p[i].1) / 2.0);
            assert!(distance(g[i - 1], middle) < 1e-9, "frame {k}: G{i}");
        }
    }
    // The traced tip: 4 samples per frame, through the frames' tips, never beyond 3 m.
    let trail = numbers(&clip["trail"][0]);
    assert_eq!(clip["sub"], 4);
    assert_eq!(trail.len(), 2 * (4 * 100 + 1));
    for k in [0, 37, 100] {
        assert_eq!(
            (trail[8 * k], trail[8 * k + 1]),
            named(&data, clip, k, &["P3"])[0]
        );
    }
    assert!(trail.chunks(2).all(|p| p[0].hypot(p[1]) <= 3.0 + 1e-9));

    let frames = [1usize, 50, 100];
    let times: Vec<String> = frames.iter().map(|&k| format!("{:e}", t[k])).collect();
    let json = run_ok(&[
        "simulate",
        "triple_pendulum",
        "--t-end",
        "4",
        "--t-out",
        &times.join(","),
        "--json",
    ]);
    let simulated: Value = serde_json::from_str(&json).expect("JSON");
    let energy = numbers(&clip["e"]);
    for (sample, &k) in simulated["samples"]
        .as_array()
        .expect("samples")
        .iter()
        .zip(&frames)
    {
        let (points, e) = triple_pendulum(&numbers(&sample["q"]), &numbers(&sample["qdot"]));
        for (page, exact) in named(&data, clip, k, &["P0", "P1", "P2", "P3"])
            .iter()
            .zip(&points)
        {
            assert!(
                distance(*page, *exact) < 1e-9,
                "frame {k}: {page:?} vs {exact:?}"
            );
        }
        assert!(
            (energy[k] - e).abs() < 1e-9,
            "frame {k}: E = {} vs {e}",
            energy[k]
        );
    }
    // E(0) = m g (0 + 0.5 + 1) = 15 J (bars along +x, up, back along −x); the drift shown is
    // (E − E₀) / max(T + |V|) to 3 digits.
    assert!((energy[0] - 15.0).abs() < 1e-12);
    let drift = numbers(&clip["de"]);
    let scale = 15.0f64.max(energy.iter().fold(0.0, |m: f64, e| m.max(e.abs())));
    for (k, d) in drift.iter().enumerate() {
        let exact = (energy[k] - 15.0) / scale;
        // The scale is at least max |E| (T + |V| ≥ |T + V|), so |d| ≤ |exact|, and the
        // printed d has 3 significant digits.
        assert!(
            d.abs() <= exact.abs() * 1.005 + 1e-15,
            "frame {k}: {d} vs {exact}"
        );
        assert!(d.abs() < 1e-6, "frame {k}: drift {d} at rtol 1e-8");
    }
}

/// The four-bar's frames close the loop (bars of 0.2, 0.6 and 0.5 m, ground pivots at
/// (0, 0) and (0.6, 0)) on every frame when the run projects onto the constraints (then
/// |Φ| ≲ 1e-12, so 1e-9 m is a margin); `--trace` chooses the traced point.
#[test]
fn four_bar_frames_close_the_loop() {
    let path = scratch("four_bar.html");
    run_ok(&[
        "animate",
        "four_bar",
        "--t-end",
        "3",
        "--stabilization",
        "projection",
        "--trace",
        "C,B",
        "-o",
        &path,
    ]);
    let data = data_of(&std::fs::read_to_string(&path).expect("page"));
    assert_eq!(names(&data), ["O", "D", "B", "C", "G1", "G2", "G3"]);
    assert_eq!(data["traces"], serde_json::json!([3, 2]));
    let clip = &data["clips"][0];
    let frames = clip["xy"].as_array().expect("frames").len();
    assert_eq!(frames, 91);
    for k in 0..frames {
        let p = named(&data, clip, k, &["O", "D", "B", "C"]);
        let (o, d, b, c) = (p[0], p[1], p[2], p[3]);
        assert!(distance(o, (0.0, 0.0)) < 1e-12 && distance(d, (0.6, 0.0)) < 1e-12);
        for (length, exact) in [
            (distance(o, b), 0.2),
            (distance(b, c), 0.6),
            (distance(d, c), 0.5),
        ] {
            assert!(
                (length - exact).abs() < 1e-9,
                "frame {k}: {length} m vs {exact} m"
            );
        }
    }
}

/// The modes page: one clip per mode of `modes --json`, each over one period 2π/ω, frame
/// `k` the closed-form geometry of the triple pendulum at `q* + s ψ sin(2π k / 60)`, with
/// `q*` and `ψ` from `modes --json` and `s` by the charts' rule: the largest linearised
/// point displacement a fifth of the mechanism's size, 3 m. At `q*` (hanging, all angles
/// −π/2) the linearised displacement of hinge `j` is `s Σ_{i ≤ j} ψᵢ` along x, so
/// `s = 0.6 / max_j |Σ_{i ≤ j} ψᵢ|`. The page's `s` comes from a central difference with
/// a step of 1e-6 (error ~1e-10 relative), hence 1e-8 m.
#[test]
fn mode_shapes_move_over_one_period() {
    let path = scratch("modes.html");
    let json = run_ok(&["modes", "triple_pendulum", "--animate", &path, "--json"]);
    let modes: Value = serde_json::from_str(&json).expect("JSON");
    assert_eq!(modes["animation"], path.as_str());
    let omega = numbers(&modes["natural_frequencies"]);
    let rest: Vec<f64> = ["theta1", "theta2", "theta3"]
        .iter()
        .map(|c| modes["operating_point"]["q"][c].as_f64().expect("q*"))
        .collect();
    let html = std::fs::read_to_string(&path).expect("page");
    assert!(html.contains("id=\"clip\""), "a mode selector");
    let data = data_of(&html);
    let clips = data["clips"].as_array().expect("clips");
    assert_eq!(clips.len(), omega.len());
    for (m, (clip, w)) in clips.iter().zip(&omega).enumerate() {
        let period = clip["period"].as_f64().expect("period");
        assert!(
            (period - TAU / w).abs() < 1e-12 * period,
            "{period} vs 2π/{w}"
        );
        let t = numbers(&clip["t"]);
        assert_eq!(t.len(), 61);
        assert!((t[60] - period).abs() < 1e-12 * period);
        let psi = numbers(&modes["mode_shapes"][m]);
        let sums = [psi[0], psi[0] + psi[1], psi[0] + psi[1] + psi[2]];
        let s = 0.6 / sums.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for k in 0..t.len() {
            let amplitude = s * (TAU * k as f64 / 60.0).sin();
            let q: Vec<f64> = rest
                .iter()
                .zip(&psi)
                .map(|(a, p)| a + amplitude * p)
                .collect();
            let (exact, _) = triple_pendulum(&q, &[0.0; 3]);
            for (page, exact) in named(&data, clip, k, &["P0", "P1", "P2", "P3"])
                .iter()
                .zip(&exact)
            {
                assert!(
                    distance(*page, *exact) < 1e-8,
                    "mode {}, frame {k}: {page:?} vs {exact:?}",
                    m + 1
                );
            }
        }
    }
}

/// `--gif`: an animated GIF of the same run, whose first frame is the whole picture with
/// the links' colour in it, and whose later frames (changed rectangles) move.
#[test]
fn gif_decodes_and_moves() {
    let (html, gif_path) = (scratch("gif.html"), scratch("anim.gif"));
    run_ok(&[
        "animate",
        "triple_pendulum",
        "--t-end",
        "1",
        "--fps",
        "10",
        "-o",
        &html,
        "--gif",
        &gif_path,
    ]);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(&gif_path).expect("gif written");
    let mut decoder = options.read_info(file).expect("a GIF");
    let (width, height) = (decoder.width(), decoder.height());
    assert!(
        width >= 240 && height >= 110 && width.max(height) <= 480,
        "{width} × {height}"
    );
    let mut count = 0;
    let mut moved = false;
    while let Some(frame) = decoder.read_next_frame().expect("frame decodes") {
        if count == 0 {
            assert_eq!(
                (frame.width, frame.height),
                (width, height),
                "first frame whole"
            );
            // The links' colour #2b59c3 is drawn.
            let link = frame
                .buffer
                .chunks(4)
                .filter(|p| p[..3] == [0x2b, 0x59, 0xc3])
                .count();
            assert!(link > 200, "{link} link pixels");
        } else {
            moved |= frame.width > 10 && frame.height > 10;
        }
        assert!(frame.delay > 0);
        count += 1;
    }
    // 11 frames at 10 fps, all kept (at most 25 per second of t).
    assert_eq!(count, 11);
    assert!(moved, "later frames change nothing");
}

/// A `--t-end` a rounding below a frame time (0.1 s at 30 fps) keeps that frame, clamped onto
/// `t_end`, instead of asking the integrator for a time past its end and failing.
#[test]
fn t_end_just_below_a_frame_time() {
    let path = scratch("t-end.html");
    let stdout = run_ok(&[
        "animate",
        "double_pendulum",
        "--t-end",
        "0.09999999999999",
        "--fps",
        "30",
        "-o",
        &path,
    ]);
    assert!(stdout.contains("(4 frames"), "{stdout}");
}

/// Bad input: clear usage errors (exit 2) before anything is written; a failed integration
/// exits 1, says where and why, and keeps the frames before it in the page.
#[test]
fn errors_are_clear() {
    let path = scratch("errors.html");
    for (args, expected) in [
        (
            vec!["--trace", "Q"],
            "has no point `Q` (points: P0, G1, P1, G2, P2, G3, P3)",
        ),
        (vec!["--fps", "0"], "--fps must be a positive number"),
        (vec!["--t-end", "1e9"], "lower --fps"),
    ] {
        let mut all = vec!["animate", "triple_pendulum", "-o", &path];
        all.extend(args);
        let out = eomgen(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
        assert!(
            !std::path::Path::new(&path).exists(),
            "written before the usage error"
        );
    }
    // RK4 with a step of 0.5 s leaves its stability region on the triple pendulum.
    let out = eomgen(&[
        "animate",
        "triple_pendulum",
        "--method",
        "rk4",
        "--dt",
        "0.5",
        "-o",
        &path,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("integration of `triple_pendulum` stopped"),
        "{stderr}"
    );
    let data = data_of(&std::fs::read_to_string(&path).expect("page of the frames before"));
    let frames = data["clips"][0]["t"].as_array().expect("t").len();
    assert!(frames > 1 && frames < 301, "{frames} frames");
    assert!(
        stderr.contains(&format!("the {frames} frames computed before it")),
        "{stderr}"
    );
}
