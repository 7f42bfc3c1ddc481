// A model file with a mistake, used as a working model would be: the only errors are the
// file's own (the macro defines `Bad` as a stand-in), not "cannot find type `Bad`" at every
// use below.
eomgen::model!("../semantics/unknown-name.yaml");

use eomgen::{
    DormandPrince54, FirstOrder, Integrator, IntegratorOptions, MechanicalSystem, ModelInfo,
    OutputTimes,
};

fn main() {
    let model = Bad::default();
    let (q, qdot) = model.initial_state();
    let _m = model.mass_matrix(&q, 0.0);
    let _ = qdot;
    let mut system = FirstOrder::new(Bad::default());
    let y0 = system.initial_state();
    let _ = DormandPrince54::new().integrate(
        &mut system,
        0.0,
        &y0,
        1.0,
        &OutputTimes::Steps,
        &IntegratorOptions::default(),
    );
}
