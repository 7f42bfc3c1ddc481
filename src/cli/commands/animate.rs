//! `eomgen animate MODEL -o FILE.html`: a simulation's `draw:` lines moving in one
//! self-contained HTML page ([`eomgen::animation`]), optionally also a GIF
//! ([`crate::cli::animation`]).

use clap::Args;

use crate::cli::animation::{DEFAULT_FPS, simulation, write_gif};
use crate::cli::error::CliError;
use crate::cli::files::{self, Outputs};
use crate::cli::integration::IntegrationArgs;
use crate::cli::output::outln;

/// Options of `eomgen animate`.
#[derive(Debug, Args)]
pub struct AnimateArgs {
    /// A bundled model's name (see `eomgen list`) or the path of any model file; it needs a
    /// `draw:` block.
    pub model: String,
    /// What to integrate and how (as `eomgen simulate`).
    #[command(flatten)]
    pub run: IntegrationArgs,
    /// The HTML file to write (self-contained: no network needed to view it).
    #[arg(short = 'o', long = "output", value_name = "FILE.html")]
    pub output: String,
    /// Frames per second of simulated time (frames at t = k / fps, from dense output).
    #[arg(long, default_value_t = DEFAULT_FPS)]
    pub fps: f64,
    /// Points whose paths are traced, comma separated (default: the file's `draw: trace`).
    #[arg(long, value_delimiter = ',', value_name = "P1,P2")]
    pub trace: Vec<String>,
    /// Also write the animation as an animated GIF (for slides).
    #[arg(long, value_name = "FILE.gif")]
    pub gif: Option<String>,
}

/// Runs `animate`.
pub fn run(args: &AnimateArgs) -> Result<(), CliError> {
    Outputs::new()
        .input(&args.model)
        .file("--output", Some(&args.output))
        .file("--gif", args.gif.as_deref())
        .check()?;
    let (animation, failure) = simulation(&args.model, &args.run, args.fps, &args.trace)?;
    let Some(animation) = animation else {
        return Err(failure.unwrap_or_else(|| CliError::failure("no frame was computed")));
    };
    let html = animation.to_html();
    write(&args.output, &html)?;
    outln!(
        "animation  {} ({} frames, {:.1} kB)",
        args.output,
        animation.clips()[0].times().len(),
        html.len() as f64 / 1e3
    );
    if let Some(path) = &args.gif {
        write_gif(&animation, path, 0)?;
        outln!("gif        {path}");
    }
    match failure {
        None => Ok(()),
        Some(e) => Err(e),
    }
}

fn write(path: &str, text: &str) -> Result<(), CliError> {
    Ok(files::write(path, text.as_bytes())?)
}
