//! Resultants in the (s, z) frame of a translation-invariant membrane and their Jacobian.
//!
//! ```text
//! N_s/(μH) = (1/λz) ∂W/∂λs      N_z/(μH) = (1/λs) ∂W/∂λz          (paper eq. 52/56)
//! ∂N_s/∂λs = W_ss/λz            ∂N_s/∂λz = W_sz/λz − W_s/λz²
//! ∂N_z/∂λs = W_sz/λs − W_z/λs²  ∂N_z/∂λz = W_zz/λs
//! ```
use tubemem_material::{MaterialError, MembraneLaw};

#[derive(Clone, Copy, Debug)]
pub(crate) struct Resultants {
    pub ns: f64,
    pub nz: f64,
    /// [[∂Ns/∂λs, ∂Ns/∂λz], [∂Nz/∂λs, ∂Nz/∂λz]]
    pub jac: [[f64; 2]; 2],
}

pub(crate) fn resultants(
    law: &dyn MembraneLaw,
    ls: f64,
    lz: f64,
) -> Result<Resultants, MaterialError> {
    let p = law.principal(ls, lz)?;
    let [ws, wz] = p.grad;
    let [[wss, wsz], [_, wzz]] = p.hess;
    Ok(Resultants {
        ns: ws / lz,
        nz: wz / ls,
        jac: [
            [wss / lz, wsz / lz - ws / (lz * lz)],
            [wsz / ls - wz / (ls * ls), wzz / ls],
        ],
    })
}
