//! The animation pages in a real browser: headless Chromium (Debian's `chromium`, which
//! `.ci/run` installs) loads `eomgen animate` pages for the triple pendulum, the four-bar
//! and the heavy top (in WebGL, as Chromium's software renderer draws it) and `modes
//! --animate` pages, and the test checks that the page's script ran
//! without an error or a `console.error`, that the animation advanced in (virtual) time at
//! the speed of time, and that a screenshot shows the drawing. Without `/usr/bin/chromium`
//! every test prints that it was skipped and passes.
//!
//! Chromium runs with a new empty profile, without network services, under a time limit (a
//! hung browser fails the test instead of hanging it). The page's first script records
//! script errors and `console.error` calls into `<pre id="errors">`, read from the DOM that
//! `--dump-dom` prints once `--virtual-time-budget` ms of page time have passed (timers run
//! in virtual time, so the check does not depend on the machine's speed).

use crate::common;

use std::io::{Read as _, Write as _};
use std::os::unix::process::CommandExt as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

const CHROMIUM: &str = "/usr/bin/chromium";
/// Longest a browser may run before the test kills it and fails.
const TIME_LIMIT: Duration = Duration::from_secs(90);
/// Page time the player runs before the DOM is read (ms).
const BUDGET_MS: u32 = 3000;
/// The page's colours: the links (#2b59c3), the traced path (#e8871e), the picture's
/// background (#fcfcfc).
const LINK: [u8; 3] = [0x2b, 0x59, 0xc3];
const TRACE: [u8; 3] = [0xe8, 0x87, 0x1e];
const BACKGROUND: [u8; 3] = [0xfc, 0xfc, 0xfc];

/// The flags of every Chromium run.
const FLAGS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
];

/// A new scratch directory for a browser test, or `None` (the test is skipped, and says so
/// on the real stderr, which the harness does not capture) when Chromium is not installed.
///
/// # Panics
/// When Chromium is missing although `EOMGEN_REQUIRE_CHROMIUM` is set (`.ci/run` sets it once
/// it has installed Chromium), so that these tests cannot pass there without running.
fn browser_dir(tag: &str) -> Option<PathBuf> {
    if Path::new(CHROMIUM).exists() {
        return Some(scratch_dir(tag));
    }
    assert!(
        std::env::var_os("EOMGEN_REQUIRE_CHROMIUM").is_none(),
        "EOMGEN_REQUIRE_CHROMIUM is set but {CHROMIUM} is missing"
    );
    let _ = writeln!(
        std::io::stderr(),
        "skipped: chromium not found (apt-get install chromium)"
    );
    None
}

/// A new empty directory for this test run.
fn scratch_dir(tag: &str) -> PathBuf {
    static COUNT: AtomicUsize = AtomicUsize::new(0);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "browser-{tag}-{}-{}",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Runs Chromium on `page` with `extra` flags, a new empty profile and the time limit;
/// returns its stdout. Panics (with the end of stderr) when it fails or runs too long.
fn chromium(page: &Path, extra: &[String]) -> String {
    let profile = scratch_dir("profile");
    let url = format!("file://{}", page.display());
    let mut child = Command::new(CHROMIUM)
        .args(FLAGS)
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(&url)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        // Its own process group, so that a hung browser is killed with its helpers.
        .process_group(0)
        .spawn()
        .expect("chromium starts");
    let mut stdout = child.stdout.take().expect("stdout");
    let mut stderr = child.stderr.take().expect("stderr");
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stdout.read_to_string(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for chromium") {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = Command::new("kill")
                .args(["-KILL", &format!("-{}", child.id())])
                .status();
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within {TIME_LIMIT:?} on {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stdout = out.join().unwrap_or_default();
    let stderr = err.join().unwrap_or_default();
    let _ = std::fs::remove_dir_all(&profile);
    let tail: String = stderr.lines().rev().take(15).collect::<Vec<_>>().join("\n");
    assert!(
        status.success(),
        "chromium failed on {url} ({status}):\n{tail}"
    );
    stdout
}

/// The value of attribute `name` on the element with `id` in `dom`.
fn attribute<'a>(dom: &'a str, id: &str, name: &str) -> Option<&'a str> {
    let at = dom.find(&format!("id=\"{id}\""))?;
    let tag_start = dom[..at].rfind('<')?;
    let tag = &dom[tag_start..tag_start + dom[tag_start..].find('>')?];
    let key = format!("{name}=\"");
    let from = tag.find(&key)? + key.len();
    Some(&tag[from..from + tag[from..].find('"')?])
}

/// The text inside the element with `id` (up to its first child tag or its end).
fn text<'a>(dom: &'a str, id: &str) -> Option<&'a str> {
    let at = dom.find(&format!("id=\"{id}\""))?;
    let from = at + dom[at..].find('>')? + 1;
    Some(&dom[from..from + dom[from..].find('<')?])
}

/// What the page shows after the virtual-time budget: its DOM.
fn dom_after_budget(page: &Path) -> String {
    chromium(
        page,
        &[
            format!("--virtual-time-budget={BUDGET_MS}"),
            "--dump-dom".to_string(),
        ],
    )
}

/// Asserts that the page recorded no script error or `console.error` (`what` names it).
fn assert_no_errors(dom: &str, what: &str) {
    let errors = text(dom, "errors").unwrap_or("?");
    assert!(errors.trim().is_empty(), "{what}: {errors}");
}

/// The frame index (`data-frame` of `#frame`) and the time (`data-t` of `#time`, s) the
/// page shows.
fn frame_and_time(dom: &str) -> (usize, f64) {
    let frame = attribute(dom, "frame", "data-frame")
        .and_then(|v| v.parse().ok())
        .expect("data-frame");
    let t = attribute(dom, "time", "data-t")
        .and_then(|v| v.parse().ok())
        .expect("data-t");
    (frame, t)
}

/// Writes `html` with `script` run at the end of its body as `dir/name`; returns the path.
fn inject(dir: &Path, name: &str, html: &str, script: &str) -> PathBuf {
    let path = dir.join(name);
    let injected = html.replacen("</body>", &format!("<script>{script}</script>\n</body>"), 1);
    std::fs::write(&path, injected).expect("write");
    path
}

/// Loads `page` and checks that it plays ([`check_plays`]); returns the DOM.
fn check_page_plays(page: &Path, seconds_per_second: f64) -> String {
    let dom = dom_after_budget(page);
    check_plays(&dom, page, seconds_per_second);
    dom
}

/// Checks the DOM of `page` after `BUDGET_MS` of page time: the player started
/// (`data-state="ready"`), no error was recorded, and the frame index and `t` have advanced —
/// by no more than the budget at 1× (the player follows the clock; 10 % allowed for the page
/// time Chromium lets pass beyond the budget, seen up to 1 %), and by at least a sixth of it
/// (it was not stuck).
fn check_plays(dom: &str, page: &Path, seconds_per_second: f64) {
    assert!(
        dom.contains("<pre id=\"errors\">"),
        "no error element in {}:\n{dom}",
        page.display()
    );
    assert_no_errors(dom, &page.display().to_string());
    assert!(
        dom.contains("<body data-state=\"ready\""),
        "the player did not start: {}",
        page.display()
    );
    let (frame, t) = frame_and_time(dom);
    let budget = f64::from(BUDGET_MS) / 1000.0 * seconds_per_second;
    assert!(
        frame > 0,
        "the animation did not advance ({})",
        page.display()
    );
    assert!(
        t > budget / 6.0 && t <= budget * 1.1,
        "t = {t} s after {budget} s of page time ({})",
        page.display()
    );
    assert!(text(dom, "time").is_some_and(|s| s.starts_with("t = ") && s != "t = 0 s"));
}

/// What one Chromium run of `page` shows after `BUDGET_MS` of page time: its DOM, and a
/// screenshot (1000 × 800) taken at the same moment, decoded as `(width, height, RGB rows)`.
/// One run rather than one for each: a Chromium start is most of a browser test's time.
fn dom_and_screenshot(page: &Path, dir: &Path) -> (String, (u32, u32, Vec<u8>)) {
    let png_path = dir.join(format!(
        "{}.png",
        page.file_stem().and_then(|s| s.to_str()).unwrap_or("page")
    ));
    let dom = chromium(
        page,
        &[
            format!("--virtual-time-budget={BUDGET_MS}"),
            "--window-size=1000,800".to_string(),
            "--hide-scrollbars".to_string(),
            format!("--screenshot={}", png_path.display()),
            "--dump-dom".to_string(),
        ],
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&png_path).expect("screenshot written"),
    ));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buffer = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buffer).expect("PNG decodes");
    let channels = info.color_type.samples();
    assert!(channels >= 3, "{:?}", info.color_type);
    let rgb: Vec<u8> = buffer[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    (dom, (info.width, info.height, rgb))
}

fn near(p: &[u8], c: [u8; 3], tolerance: i32) -> bool {
    p.iter()
        .zip(c)
        .all(|(a, b)| (i32::from(*a) - i32::from(b)).abs() <= tolerance)
}

/// The screenshot of `page` is not blank: the picture's background covers part of it, a good
/// share of the pixels are neither white nor that background, and the links' (and, if asked,
/// the trace's) colour is drawn.
fn check_screenshot(page: &Path, (width, height, rgb): &(u32, u32, Vec<u8>), traced: bool) {
    assert_eq!((*width, *height), (1000, 800));
    let pixels = rgb.len() / 3;
    let count = |f: &dyn Fn(&[u8]) -> bool| rgb.chunks(3).filter(|p| f(p)).count();
    let background = count(&|p| near(p, BACKGROUND, 1));
    let ink = count(&|p| !near(p, [255, 255, 255], 2) && !near(p, BACKGROUND, 2));
    let link = count(&|p| near(p, LINK, 24));
    let trace = count(&|p| near(p, TRACE, 24));
    let name = page.display();
    // The picture fills most of the window; grid, links, joints, text and controls cover a
    // few per cent of it; 4 px links over a metre or more are thousands of pixels.
    assert!(
        background > pixels / 4,
        "{name}: background {background} of {pixels}"
    );
    assert!(
        ink > pixels / 50,
        "{name}: only {ink} of {pixels} pixels drawn"
    );
    assert!(link > 1000, "{name}: {link} pixels of the links' colour");
    if traced {
        assert!(trace > 100, "{name}: {trace} pixels of the trace's colour");
    }
}

/// Writes `eomgen args… -o/--animate PATH` into `dir` and returns the path.
fn page(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let path = dir.join(name);
    let path_text = path.to_str().expect("UTF-8 path");
    let mut all: Vec<&str> = args.to_vec();
    all.push(path_text);
    common::eomgen_ok(&all);
    path
}

#[test]
fn triple_pendulum_plays_in_chromium() {
    let Some(dir) = browser_dir("triple") else {
        return;
    };
    let path = page(
        &dir,
        "triple_pendulum.html",
        &["animate", "triple_pendulum", "-o"],
    );
    let (dom, screenshot) = dom_and_screenshot(&path, &dir);
    check_plays(&dom, &path, 1.0);
    check_screenshot(&path, &screenshot, true);
}

#[test]
fn four_bar_plays_in_chromium() {
    let Some(dir) = browser_dir("four-bar") else {
        return;
    };
    let path = page(&dir, "four_bar.html", &["animate", "four_bar", "-o"]);
    let (dom, screenshot) = dom_and_screenshot(&path, &dir);
    check_plays(&dom, &path, 1.0);
    // The energy and its drift are shown.
    assert!(text(&dom, "energy").is_some_and(|s| s.starts_with("E = ") && s.ends_with(" J")));
    assert!(text(&dom, "drift").is_some_and(|s| s.contains("E₀")));
    check_screenshot(&path, &screenshot, true);
}

/// The four-bar's one mode (6.398 rad/s, period 0.982 s) plays at one cycle per 2 s, so
/// after the budget `t` has advanced by at most budget × 0.982 / 2 modulo the period.
#[test]
fn mode_shapes_play_in_chromium() {
    let Some(dir) = browser_dir("modes") else {
        return;
    };
    let path = page(
        &dir,
        "four_bar_modes.html",
        &["modes", "four_bar", "--animate"],
    );
    let (dom, screenshot) = dom_and_screenshot(&path, &dir);
    assert_no_errors(&dom, "modes page");
    assert!(dom.contains("<body data-state=\"ready\">"));
    let (frame, t) = frame_and_time(&dom);
    assert!(frame > 0, "the mode did not move");
    assert!(
        (0.0..0.982).contains(&t),
        "mode time {t} outside one period"
    );
    assert!(dom.contains("<select id=\"clip\""), "a mode selector");
    check_screenshot(&path, &screenshot, false);
}

/// The check can fail: a page with a script error and a call of `console.error` has both
/// messages in `#errors`.
#[test]
fn errors_in_the_page_are_seen() {
    let Some(dir) = browser_dir("errors") else {
        return;
    };
    let good = page(
        &dir,
        "good.html",
        &["animate", "four_bar", "--t-end", "1", "-o"],
    );
    let html = std::fs::read_to_string(&good).expect("page");
    // Both in one page, each in a script element of its own (a thrown error ends only its
    // own script).
    let thrown = inject(&dir, "thrown.html", &html, "no_such_function();");
    let html = std::fs::read_to_string(&thrown).expect("page");
    let both = inject(&dir, "both.html", &html, "console.error('bad frame');");
    let dom = dom_after_budget(&both);
    let errors = text(&dom, "errors").unwrap_or("");
    for expected in ["no_such_function", "console.error: bad frame"] {
        assert!(errors.contains(expected), "{expected}: `{errors}`");
    }
}

/// The controls: a space key press pauses the player (the frame stays where it was and the
/// button offers "Play"), the scrubber shows the frame it is moved to, and the speed
/// selector scales the page's clock (at 0.25× a 3 s budget plays 0.75 s, against 3 s at
/// 1×; the bounds allow 10 % of extra page time and a slow start).
#[test]
fn controls_work_in_chromium() {
    let Some(dir) = browser_dir("controls") else {
        return;
    };
    let good = page(&dir, "good.html", &["animate", "triple_pendulum", "-o"]);
    let html = std::fs::read_to_string(&good).expect("page");
    let run = |name: &str, script: &str| {
        let dom = dom_after_budget(&inject(&dir, name, &html, script));
        assert_no_errors(&dom, name);
        let (frame, t) = frame_and_time(&dom);
        (dom, frame, t)
    };
    let (dom, frame, _) = run(
        "space.html",
        "document.dispatchEvent(new KeyboardEvent('keydown', {key: ' ', code: 'Space', bubbles: true}));",
    );
    assert_eq!(frame, 0, "space did not pause");
    assert_eq!(text(&dom, "play"), Some("Play"));
    let (_, frame, t) = run(
        "scrub.html",
        "var s = document.getElementById('scrub'); s.value = '150'; s.dispatchEvent(new Event('input'));",
    );
    assert_eq!(
        (frame, t),
        (150, 5.0),
        "the scrubber moved to frame 150 (t = 5 s) and paused"
    );
    let (_, _, t) = run(
        "speed.html",
        "var v = document.getElementById('speed'); v.value = '0.25'; v.dispatchEvent(new Event('change'));",
    );
    assert!(t > 0.4 && t <= 0.825, "at 0.25× after 3 s: t = {t}");
}

/// The course report (`eomgen report`) loads in Chromium with its sections and MathML, and
/// the animation it embeds plays like one written by `eomgen animate`.
#[test]
fn report_loads_and_its_animation_plays_in_chromium() {
    let Some(dir) = browser_dir("report") else {
        return;
    };
    common::eomgen_ok(&[
        "report",
        "--models",
        "triple_pendulum,four_bar",
        "-o",
        dir.to_str().expect("UTF-8 path"),
    ]);
    let dom = dom_after_budget(&dir.join("index.html"));
    for id in ["triple_pendulum", "four_bar"] {
        assert!(dom.contains(&format!("<section id=\"{id}\">")), "{id}");
        assert!(
            dom.contains(&format!("src=\"{id}/animation.html\"")),
            "{id}: animation embedded"
        );
    }
    assert!(dom.contains("<math"), "MathML equations");
    check_page_plays(&dir.join("triple_pendulum").join("animation.html"), 1.0);
}

/// Pixels of the first body's colour (#c8553d, lit and seen through: red well above green
/// and blue) in a screenshot.
fn body_pixels(rgb: &[u8]) -> usize {
    (rgb.chunks(3))
        .filter(|p| {
            let (r, g, b) = (i32::from(p[0]), i32::from(p[1]), i32::from(p[2]));
            r > g + 50 && r > b + 50
        })
        .count()
}

/// A 3-D model's page draws it in WebGL (issue 53, item 5): the heavy top plays with no
/// error, the page says it shows the WebGL view, and a screenshot shows the top's disc (tens
/// of thousands of pixels of its colour) in the iso view and from the top (`#top`, set here
/// by a script). Without WebGL the page keeps its isometric drawing and says why, with no
/// error; a planar model's page has no 3-D view at all.
#[test]
fn three_d_models_play_in_webgl() {
    let Some(dir) = browser_dir("webgl") else {
        return;
    };
    let path = page(&dir, "heavy_top.html", &["animate", "heavy_top", "-o"]);
    let (dom, (_, _, rgb)) = dom_and_screenshot(&path, &dir);
    check_plays(&dom, &path, 1.0);
    assert!(dom.contains("data-view=\"webgl\""), "no WebGL view");
    assert!(dom.contains("data-camera=\"iso\""), "not the iso view");
    let body = body_pixels(&rgb);
    assert!(body > 10_000, "iso view: {body} pixels of the top's colour");
    let html = std::fs::read_to_string(&path).expect("page");
    let top = inject(&dir, "top.html", &html, "window.location.hash = 'top';");
    let (dom, (_, _, rgb)) = dom_and_screenshot(&top, &dir);
    assert_no_errors(&dom, "top view");
    assert!(dom.contains("data-camera=\"top\""), "not the top view");
    let seen = body_pixels(&rgb);
    assert!(seen > 10_000, "top view: {seen} pixels of the top's colour");
    // Without WebGL: the isometric drawing, a note, no error.
    let dom = chromium(
        &path,
        &[
            format!("--virtual-time-budget={BUDGET_MS}"),
            "--disable-webgl".to_string(),
            "--dump-dom".to_string(),
        ],
    );
    assert_no_errors(&dom, "without WebGL");
    assert!(dom.contains("data-view=\"svg\""), "no fallback");
    assert!(
        text(&dom, "view-note").is_some_and(|s| s.contains("isometric drawing shown")),
        "no note"
    );
    // The modes of a 3-D model play in WebGL too; a planar model has no 3-D view.
    let modes = page(
        &dir,
        "furuta_modes.html",
        &["modes", "furuta_pendulum", "--animate"],
    );
    let dom = dom_after_budget(&modes);
    assert_no_errors(&dom, "3-D modes page");
    assert!(dom.contains("data-view=\"webgl\""), "modes: no WebGL view");
    let planar = page(
        &dir,
        "four_bar.html",
        &["animate", "four_bar", "--t-end", "1", "-o"],
    );
    let html = std::fs::read_to_string(&planar).expect("page");
    assert!(
        !html.contains("id=\"three-gz\"") && !html.contains("<canvas"),
        "a planar page with a 3-D view"
    );
}
