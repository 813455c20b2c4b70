//! What loads the model at one step ([`Load`]: the gas [`Loading`] and the rigid planes) and
//! a configuration ([`State`]).

use super::*;

/// How the enclosed gas is loaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Loading {
    /// prescribed reduced pressure ϖ
    Pressure(f64),
    /// prescribed total enclosed volume (whole tube, all symmetry copies)
    Volume(f64),
    /// prescribed coordinate of one degree of freedom (node, component), pressure as multiplier
    Node {
        node: usize,
        component: usize,
        target: f64,
    },
    /// closed isothermal gas: p · V_total = `pv` (Boyle's constant)
    Gas { pv: f64 },
}

/// Everything that loads the model at one step: the gas loading and the rigid planes.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    pub loading: Loading,
    pub contact: Option<Contact>,
}

impl Load {
    pub fn new(loading: Loading) -> Self {
        Self {
            loading,
            contact: None,
        }
    }
    pub fn pressure(p: f64) -> Self {
        Self::new(Loading::Pressure(p))
    }
    pub fn with_contact(loading: Loading, contact: Contact) -> Self {
        Self {
            loading,
            contact: Some(contact),
        }
    }
    /// Boyle's constant, for closed gas.
    pub fn gas(&self) -> Option<f64> {
        match self.loading {
            Loading::Gas { pv } => Some(pv),
            _ => None,
        }
    }
}

/// A converged (or trial) configuration.
#[derive(Clone, Debug)]
pub struct State {
    pub x: Vec<[f64; 3]>,
    /// reduced pressure ϖ
    pub p: f64,
    /// the planes' load parameter λ of a closed-gas arc-length path ([`MovingPlanes`]);
    /// unused (0) elsewhere
    pub planes: f64,
    /// the contact multipliers of an augmented-Lagrangian contact
    /// ([`crate::contact::Enforcement::Augmented`]), element major, then Gauss point, then
    /// plane, [`crate::contact::HISTORY`] values each ([`Contact::point`],
    /// [`Contact::element_history`]); empty: none (the penalty alone)
    pub multipliers: Vec<f64>,
}
