//! Code verification by the method of manufactured solutions (Roache, *Code Verification by
//! the Method of Manufactured Solutions*, 2002; Salari & Knupp, SAND2000-1444).
//!
//! A smooth map of space x*(X) ([`field`]) restricted to the capped tube's exact reference
//! surface ([`surface`]: a cylinder with hemispherical caps) is made an equilibrium by the body
//! force per reference area ([`body`])
//!
//! ```text
//! b = −(1/√G) ∂_β (√G S^{αβ} x*_{,α}) − p (x*_{,1} × x*_{,2}) / √G
//! ```
//! (the strong form of ∫ S^{αβ} x_{,α}·δx_{,β} dA0 = ∫ (b dA0 + p n da)·δx, in any local chart
//! ξ of the surface: G_{αβ} = X_{,α}·X_{,β}, S^{αβ} = 2 (W_a G^{αβ} + W_b det C (C⁻¹)^{αβ}) the
//! law's second Piola–Kirchhoff stress, C_{αβ} = x_{,α}·x_{,β}). The derivatives of the
//! geometry and of x* come from second-order dual numbers in the chart's coordinates, those of
//! the law from its own second derivatives: b is exact to round-off for any law of
//! `tubemem-material`, the relaxed law and the laws written as text included.
//!
//! [`study`] adds b to a model as a force term ([`body::BodyForce`], through the public term
//! interface), solves with the loading chosen (none, a pressure, the volume, or the gas closed
//! in), and measures the error against x* in position (L2 and max, at the Gauss points and the
//! nodes) and in the resultants.

pub mod body;
pub mod field;
pub mod study;
pub mod surface;
