//! Normal sub-models: the elastic normal force.
use super::{NormalModel, SubModel};
use crate::material::ContactModel;

/// The linear normal spring, `Fn = kn * overlap` (paper Eq. 3, evaluated from
/// the overlap as PFC does); no history.
#[derive(Debug, Clone, Copy)]
pub struct LinearSpring;

impl SubModel for LinearSpring {
    const NAME: &'static str = "linear spring";
    const HISTORY: usize = 0;
    const LANES: bool = true;
}

impl NormalModel for LinearSpring {
    #[inline(always)]
    fn elastic_force(model: &ContactModel, overlap: f64, _history: &mut [f64]) -> f64 {
        model.normal_stiffness * overlap
    }
}
