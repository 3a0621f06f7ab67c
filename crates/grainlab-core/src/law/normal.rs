//! Normal sub-models: the elastic normal force.
use super::real::Real;
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

impl LinearSpring {
    /// `kn * overlap` (N), of one contact or of four lanes.
    #[inline(always)]
    pub fn force<R: Real>(normal_stiffness: R, overlap: R) -> R {
        normal_stiffness * overlap
    }
}

impl NormalModel for LinearSpring {
    #[inline(always)]
    fn elastic_force(model: &ContactModel, overlap: f64, _history: &mut [f64]) -> f64 {
        Self::force(model.normal_stiffness, overlap)
    }
}
