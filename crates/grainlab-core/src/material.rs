//! Contact models per pair of material groups (particle-particle, particle-wall, ...).
use serde::{Deserialize, Serialize};

use crate::error::{require_non_negative, require_positive, EngineError, Result};
use crate::law::hertz::HertzConstants;
use crate::state::MAX_GROUPS;

/// Which contact law a pair of material groups follows (docs/contact-law.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ContactLaw {
    /// Linear springs `kn`, `ks` with Coulomb friction and optional dashpots
    /// (the paper's law, PFC's linear model).
    #[default]
    Linear,
    /// Hertz's normal force and Mindlin's no-slip tangential stiffness from the
    /// grains' Young's modulus and Poisson ratio, damped to a coefficient of
    /// restitution, with Coulomb friction (LAMMPS `pair granular hertz/material
    /// ... damping coeff_restitution tangential mindlin`).
    HertzMindlin,
}

impl ContactLaw {
    /// The law's name as the configuration spells it.
    pub fn name(self) -> &'static str {
        match self {
            ContactLaw::Linear => "linear",
            ContactLaw::HertzMindlin => "hertz_mindlin",
        }
    }

    /// The law named `name` (`linear` or `hertz_mindlin`).
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "linear" => Ok(ContactLaw::Linear),
            "hertz_mindlin" => Ok(ContactLaw::HertzMindlin),
            other => Err(EngineError::invalid(
                "contact_law",
                format!("unknown law {other:?} (known: linear, hertz_mindlin)"),
            )),
        }
    }
}

/// Parameters of a pair's contact law with Coulomb friction (docs/contact-law.md).
///
/// For the linear law `normal_stiffness` and `shear_stiffness` are *contact*
/// stiffnesses (N/m) and the damping ratios fractions of critical damping of
/// the viscous dashpots (0 disables them; local damping is separate, per
/// particle). For Hertz-Mindlin the stiffnesses follow from
/// `youngs_modulus` and `poisson_ratio` and the overlap, the damping from
/// `restitution`; `normal_stiffness` and `shear_stiffness` are then not read.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactModel {
    /// Normal contact stiffness kn (N/m).
    pub normal_stiffness: f64,
    /// Shear contact stiffness ks (N/m).
    pub shear_stiffness: f64,
    /// Coulomb friction coefficient mu.
    pub friction: f64,
    /// Normal viscous damping, fraction of critical `2 sqrt(m* kn)`.
    pub normal_damping_ratio: f64,
    /// Shear viscous damping, fraction of critical `2 sqrt(m* ks)`.
    pub shear_damping_ratio: f64,
    /// Rolling friction coefficient mu_r: the rolling moment is capped at
    /// `mu_r R* F_n` (0, the default, disables rolling resistance).
    pub rolling_friction: f64,
    /// Rolling stiffness k_r (N m/rad); 0 (the default) for the rule
    /// `2.25 k_n mu_r^2 R*^2` (Iwashita and Oda; Ai et al. 2011).
    pub rolling_stiffness: f64,
    /// Rolling viscous damping, fraction of critical `2 sqrt(I_r k_r)`,
    /// acting while the rolling spring is below its cap.
    pub rolling_damping_ratio: f64,
    /// Whether the two groups interact at all; `false` lets them pass through
    /// each other (e.g. the disks of a membrane chain, held together by bonds).
    pub enabled: bool,
    /// The contact law of the pair.
    pub law: ContactLaw,
    /// Young's modulus E of the grains (Pa), Hertz-Mindlin only.
    pub youngs_modulus: f64,
    /// Poisson ratio nu of the grains, in (-1, 0.5); Hertz-Mindlin only.
    pub poisson_ratio: f64,
    /// Normal coefficient of restitution e in (0, 1]; Hertz-Mindlin only (1: elastic).
    pub restitution: f64,
}

impl ContactModel {
    /// Linear spring model without viscous damping.
    pub fn linear(normal_stiffness: f64, shear_stiffness: f64, friction: f64) -> Self {
        ContactModel {
            normal_stiffness,
            shear_stiffness,
            friction,
            normal_damping_ratio: 0.0,
            shear_damping_ratio: 0.0,
            rolling_friction: 0.0,
            rolling_stiffness: 0.0,
            rolling_damping_ratio: 0.0,
            enabled: true,
            law: ContactLaw::Linear,
            youngs_modulus: 0.0,
            poisson_ratio: 0.0,
            restitution: 1.0,
        }
    }

    /// Hertz-Mindlin between grains of Young's modulus `youngs_modulus` (Pa)
    /// and Poisson ratio `poisson_ratio`, damped to the coefficient of
    /// restitution `restitution`, with Coulomb friction `friction`.
    pub fn hertz_mindlin(
        youngs_modulus: f64,
        poisson_ratio: f64,
        restitution: f64,
        friction: f64,
    ) -> Self {
        ContactModel {
            law: ContactLaw::HertzMindlin,
            youngs_modulus,
            poisson_ratio,
            restitution,
            // not read by the law; kept valid for what checks every model's fields
            normal_stiffness: 1.0,
            shear_stiffness: 1.0,
            ..ContactModel::linear(1.0, 1.0, friction)
        }
    }

    /// Checks every field's range.
    pub fn validate(&self, field: &str) -> Result<()> {
        if self.law == ContactLaw::HertzMindlin {
            self.validate_hertz_mindlin(field)?;
        }
        require_positive(&format!("{field}.normal_stiffness"), self.normal_stiffness)?;
        require_positive(&format!("{field}.shear_stiffness"), self.shear_stiffness)?;
        require_non_negative(&format!("{field}.friction"), self.friction)?;
        require_non_negative(
            &format!("{field}.normal_damping_ratio"),
            self.normal_damping_ratio,
        )?;
        require_non_negative(
            &format!("{field}.shear_damping_ratio"),
            self.shear_damping_ratio,
        )?;
        require_non_negative(&format!("{field}.rolling_friction"), self.rolling_friction)?;
        require_non_negative(
            &format!("{field}.rolling_stiffness"),
            self.rolling_stiffness,
        )?;
        require_non_negative(
            &format!("{field}.rolling_damping_ratio"),
            self.rolling_damping_ratio,
        )?;
        Ok(())
    }

    /// The ranges of Hertz-Mindlin's parameters.
    fn validate_hertz_mindlin(&self, field: &str) -> Result<()> {
        require_positive(&format!("{field}.youngs_modulus"), self.youngs_modulus)?;
        let nu = self.poisson_ratio;
        if !(nu > -1.0 && nu < 0.5) {
            return Err(EngineError::invalid(
                format!("{field}.poisson_ratio"),
                format!("{nu} is outside (-1, 0.5)"),
            ));
        }
        let e = self.restitution;
        if !(e > 0.0 && e <= 1.0) {
            return Err(EngineError::invalid(
                format!("{field}.restitution"),
                format!("{e} is outside (0, 1]"),
            ));
        }
        if self.normal_damping_ratio != 0.0 || self.shear_damping_ratio != 0.0 {
            return Err(EngineError::invalid(
                format!("{field}.normal_damping_ratio"),
                "Hertz-Mindlin is damped by its restitution, not by damping ratios (give 0)",
            ));
        }
        Ok(())
    }
}

/// Symmetric table of contact models indexed by the two contacting groups.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MaterialTable {
    models: Vec<ContactModel>,
    /// Each Hertz-Mindlin model's constants, at its index (default for a linear one).
    hertz: Vec<HertzConstants>,
    /// What the force kernels ask of the whole table at every step, kept with
    /// it (a scan of every pair's model each step cost the step a few percent).
    summary: TableSummary,
}

impl HertzConstants {
    /// The constants of a Hertz-Mindlin `model`; zero for a linear one.
    fn of_model(model: &ContactModel) -> Self {
        match model.law {
            ContactLaw::HertzMindlin => HertzConstants::of(model),
            ContactLaw::Linear => HertzConstants::default(),
        }
    }
}

/// The table's answers to the force kernels' questions, made anew at every change.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct TableSummary {
    single_undamped_model: Option<ContactModel>,
    undamped: bool,
    rolling: bool,
    rolling_damped: bool,
    all_hertz: bool,
}

impl TableSummary {
    fn of(models: &[ContactModel]) -> Self {
        let undamped = models.iter().all(|m| {
            m.law == ContactLaw::Linear
                && m.normal_damping_ratio == 0.0
                && m.shear_damping_ratio == 0.0
        });
        let first = models.first().copied();
        let single = first.filter(|f| undamped && models.iter().all(|m| m == f));
        TableSummary {
            single_undamped_model: single,
            undamped,
            rolling: models.iter().any(|m| m.rolling_friction != 0.0),
            rolling_damped: models
                .iter()
                .any(|m| m.rolling_friction != 0.0 && m.rolling_damping_ratio > 0.0),
            all_hertz: models.iter().all(|m| m.law == ContactLaw::HertzMindlin),
        }
    }
}

impl MaterialTable {
    /// Every pair of groups uses `model`.
    pub fn uniform(model: ContactModel) -> Result<Self> {
        model.validate("contact_model")?;
        let models = vec![model; MAX_GROUPS * MAX_GROUPS];
        let summary = TableSummary::of(&models);
        let hertz = models.iter().map(HertzConstants::of_model).collect();
        Ok(MaterialTable {
            models,
            hertz,
            summary,
        })
    }

    /// Checks that `a` and `b` name material groups.
    pub fn check_groups(a: usize, b: usize) -> Result<()> {
        for (name, g) in [("group_a", a), ("group_b", b)] {
            if g >= MAX_GROUPS {
                return Err(EngineError::invalid(
                    name,
                    format!("group {g} out of range 0..{MAX_GROUPS}"),
                ));
            }
        }
        Ok(())
    }

    /// Sets the model between groups `a` and `b` (both orders).
    pub fn set(&mut self, a: usize, b: usize, model: ContactModel) -> Result<()> {
        Self::check_groups(a, b)?;
        model.validate("contact_model")?;
        self.models[a * MAX_GROUPS + b] = model;
        self.models[b * MAX_GROUPS + a] = model;
        self.hertz[a * MAX_GROUPS + b] = HertzConstants::of_model(&model);
        self.hertz[b * MAX_GROUPS + a] = HertzConstants::of_model(&model);
        self.summary = TableSummary::of(&self.models);
        Ok(())
    }

    /// Whether groups `a` and `b` interact.
    #[inline(always)]
    pub fn interacts(&self, a: u8, b: u8) -> bool {
        self.models[Self::index(a, b) as usize].enabled
    }

    /// Index of the model between groups `a` and `b`, for [`MaterialTable::by_index`].
    #[inline(always)]
    pub fn index(a: u8, b: u8) -> u16 {
        a as u16 * MAX_GROUPS as u16 + b as u16
    }

    /// The model between groups `a` and `b`.
    pub fn get(&self, a: u8, b: u8) -> &ContactModel {
        &self.models[Self::index(a, b) as usize]
    }

    /// Number of stored models (valid indices are below it).
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// True when no model is stored (never, for a table made by [`MaterialTable::new`]).
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// The model stored at `index`.
    #[inline(always)]
    pub fn by_index(&self, index: u16) -> &ContactModel {
        &self.models[index as usize]
    }

    /// The Hertz-Mindlin constants of the model stored at `index` (zero for a linear one).
    #[inline(always)]
    pub fn hertz_constants(&self, index: u16) -> &HertzConstants {
        &self.hertz[index as usize]
    }

    /// The model every pair of groups uses, if they all use one and it has no
    /// dashpot: the force kernels then keep it in registers and skip the
    /// dashpot terms (same results, fewer instructions).
    pub fn single_undamped_model(&self) -> Option<ContactModel> {
        self.summary.single_undamped_model
    }

    /// Whether no model of the table has a dashpot, and every one is linear
    /// (the force kernels' dashpot-free loops, the four-pair lanes among them,
    /// evaluate the linear law only; a Hertz-Mindlin pair runs the law itself).
    pub fn undamped(&self) -> bool {
        self.summary.undamped
    }

    /// Whether every pair of groups uses Hertz-Mindlin (the pair loop then
    /// runs that law inlined, the linear loops keep theirs without it).
    pub fn all_hertz(&self) -> bool {
        self.summary.all_hertz
    }

    /// Whether any model of the table has rolling resistance (`rolling_friction`
    /// above 0): the four-pair lanes then evaluate the rolling law too.
    pub fn rolling(&self) -> bool {
        self.summary.rolling
    }

    /// Whether any model with rolling resistance has a rolling dashpot: the
    /// four-pair lanes then gather the masses and inertias it reads.
    pub fn rolling_damped(&self) -> bool {
        self.summary.rolling_damped
    }

    /// Largest normal or shear stiffness of any model involving group `g`, for
    /// a particle of radius `radius`: a Hertz-Mindlin model's tangent
    /// stiffnesses at the largest overlap a run allows, `max_overlap_ratio`
    /// of the radius, between two such particles
    /// ([`crate::law::hertz::tangent_stiffness`]).
    pub fn max_stiffness_for_group(&self, g: u8, radius: f64, max_overlap_ratio: f64) -> f64 {
        (0..MAX_GROUPS as u8)
            .map(|other| {
                let m = self.get(g, other);
                match m.law {
                    ContactLaw::Linear => m.normal_stiffness.max(m.shear_stiffness),
                    ContactLaw::HertzMindlin => {
                        let r_star = 0.5 * radius;
                        let overlap = max_overlap_ratio * radius;
                        let (kn, ks) = crate::law::hertz::tangent_stiffness(m, overlap, r_star);
                        kn.max(ks)
                    }
                }
            })
            .fold(0.0, f64::max)
    }
}
