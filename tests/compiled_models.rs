//! Thirteen bundled model files compiled into the test binary by `eomgen::model!`, for the
//! tests that compare the macro's code with the same file compiled at run time (the path every
//! bundled model takes in the program). Chosen to cover the kinds of equation the code
//! generators write: energies and points (`double_pendulum`, `double_pendulum_points`), a
//! diagonal mass matrix and central forces (`figure_eight`, `two_body`, `three_body_circle`,
//! with interactions and outputs), a 3-D body (`heavy_top`), a holonomic constraint
//! (`simple_pendulum_cartesian`) and a time-dependent one, with `cosh` of time in a point
//! (`bead_spinning_rod`), a time-dependent load (`forced_oscillator`), `asin`
//! (`slider_crank`), `sqrt` of the rates and events (`projectile_drag`), functions without a
//! Taylor recurrence (`two_masses`: `sign`, `step`) and rolling constraints
//! (`whipple_bicycle`). The other bundled files go through the macro's code generator in
//! `determinism.rs` (`eomgen equations NAME --rust`: generated and parsed, not compiled).

use eomgen::{FirstOrder, ModelInfo};

macro_rules! compiled {
    ($($module:ident: $ty:ident = $file:literal;)*) => {
        $(
            pub mod $module {
                eomgen::model!($file);
            }
        )*

        /// Every model compiled here: `(name, constructor)`.
        pub const ALL: &[(&str, fn() -> Box<dyn ModelInfo + Send>)] = &[
            $((stringify!($module), || Box::new(FirstOrder::new($module::$ty::default()))),)*
        ];
    };
}

compiled! {
    bead_spinning_rod: BeadSpinningRod = "../models/bead_spinning_rod.yaml";
    double_pendulum: DoublePendulum = "../models/double_pendulum.yaml";
    double_pendulum_points: DoublePendulumPoints = "../models/double_pendulum_points.yaml";
    figure_eight: FigureEight = "../models/figure_eight.yaml";
    forced_oscillator: ForcedOscillator = "../models/forced_oscillator.yaml";
    heavy_top: HeavyTop = "../models/heavy_top.yaml";
    projectile_drag: ProjectileDrag = "../models/projectile_drag.yaml";
    simple_pendulum_cartesian: SimplePendulumCartesian = "../models/simple_pendulum_cartesian.yaml";
    slider_crank: SliderCrank = "../models/slider_crank.yaml";
    three_body_circle: ThreeBodyCircle = "../models/three_body_circle.yaml";
    two_body: TwoBody = "../models/two_body.yaml";
    two_masses: TwoMasses = "../models/two_masses.yaml";
    whipple_bicycle: WhippleBicycle = "../models/whipple_bicycle.yaml";
}

/// The bundled model `name` compiled by `model!`, if it is one of these.
pub fn make(name: &str) -> Option<Box<dyn ModelInfo + Send>> {
    ALL.iter().find(|(n, _)| *n == name).map(|(_, make)| make())
}

/// Every compiled model is the bundled model of its name (its file's `name:`).
#[test]
fn each_compiled_model_is_the_bundled_model_of_its_name() {
    for (name, make) in ALL {
        assert_eq!(make().description().name, *name);
        assert!(eomgen::models::find(name).is_some(), "{name}");
    }
}

/// The bundled model `entry` compiled by `model!` if it is one of these, else its file on the
/// run-time compiler's interpreter backend: for a comparison with the native code the program
/// runs, always another route to the same bits.
pub fn make_or_interpreted(entry: &eomgen::models::ModelEntry) -> Box<dyn ModelInfo + Send> {
    make(entry.name).unwrap_or_else(|| {
        let options = eomgen::LoadOptions {
            backend: Some(eomgen::Backend::Interpreter),
            ..eomgen::LoadOptions::default()
        };
        let model = entry
            .load_with(options)
            .unwrap_or_else(|e| panic!("{}: {e}", entry.file));
        Box::new(eomgen::DynFirstOrder::new(model))
    })
}
