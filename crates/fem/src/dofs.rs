//! Degrees of freedom and constraints: which nodal components are free, and their equation
//! numbers.
//!
//! * Symmetry planes: the normal displacement is fixed on each symmetry plane of the mesh.
//! * Rigid-body modes left by the symmetry are pinned on nodes whose motion the symmetry of the
//!   problem already forbids (so the pins carry no load): u_x = u_y = 0 on the axis x = y = 0,
//!   u_x = 0 at the node of largest y on the line x = z = 0, u_z = 0 at one node on z = 0.
//!   Where the problem does not forbid that motion (planes not symmetric about x = 0 or y = 0,
//!   such as a V-groove, move the tube sideways), [`DofMap::with_soft_pins`] leaves those
//!   components free and lists them as [`SoftPin`]s, held by a spring (of stiffness
//!   [`SOFT_PIN_STIFFNESS`] in runs) to their reference position instead (the model assembles
//!   it): the
//!   rigid mode stays removed while nothing else holds it, and the spring's force, κ_s times
//!   the translation, is negligible once the planes do.
//! * Rigid plugs: the ring nodes keep x and y (tied to the disc) and share one axial equation,
//!   the disc's translation.

use tubemem_mesh::Mesh;

/// The stiffness (per μH/R², a spring per node) of a soft rigid-mode pin: 1e-8, so that a
/// translation of 0.1 R costs a force of 1e-9 μH, far below the Newton tolerance on forces of
/// order μH, while the tangent keeps a positive pivot of that size (the factorization's pivots
/// reach 1e2: a condition number of about 1e10, within double precision).
pub const SOFT_PIN_STIFFNESS: f64 = 1e-8;

/// A rigid-mode pin turned into a spring: node `node`'s component `component` (equation `eq`)
/// is held to its reference position by a spring of stiffness `stiffness`
/// ([`SOFT_PIN_STIFFNESS`] in runs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftPin {
    pub node: usize,
    pub component: usize,
    pub eq: usize,
    pub stiffness: f64,
}

/// The equation number of every dof (3 per node) and of every plug's axial translation.
#[derive(Clone, Debug)]
pub struct DofMap {
    eq: Vec<Option<usize>>,
    n_eq: usize,
    plug_eq: Vec<Option<usize>>,
    soft: Vec<SoftPin>,
}

impl DofMap {
    /// Number the dofs of a checked mesh.
    pub fn new(mesh: &Mesh) -> Self {
        Self::with_soft_pins(mesh, [false, false], SOFT_PIN_STIFFNESS)
    }

    /// [`DofMap::new`] with the rigid-mode pins of component x (`soft[0]`) and y (`soft[1]`)
    /// made springs of stiffness `stiffness` ([`SoftPin`]); symmetry-plane conditions stay
    /// fixed.
    pub fn with_soft_pins(mesh: &Mesh, soft: [bool; 2], stiffness: f64) -> Self {
        let nn = mesh.nodes.len();
        let mut fixed = vec![false; 3 * nn];
        // the rigid-mode pins, which `soft` may make springs
        let mut pinned = vec![false; 3 * nn];
        let on: Vec<Vec<bool>> = (0..3).map(|ax| mesh.on_plane(ax)).collect();
        let planes = mesh.symmetry.planes();
        for &ax in planes {
            for i in 0..nn {
                if on[ax][i] {
                    fixed[3 * i + ax] = true;
                }
            }
        }
        // translations x, y and rotations about x, y
        if !planes.contains(&0) || !planes.contains(&1) {
            for i in 0..nn {
                if on[0][i] && on[1][i] {
                    for c in 0..2 {
                        if !fixed[3 * i + c] {
                            pinned[3 * i + c] = true;
                        }
                    }
                }
            }
        }
        // rotation about z
        if !planes.contains(&0) && !planes.contains(&1) {
            if let Some(i) = (0..nn)
                .filter(|&i| on[0][i] && on[2][i])
                .max_by(|&a, &b| mesh.nodes[a][1].total_cmp(&mesh.nodes[b][1]))
            {
                pinned[3 * i] = !fixed[3 * i];
            }
        }
        // translation z
        if !planes.contains(&2) {
            if let Some(i) = (0..nn).find(|&i| on[2][i]) {
                fixed[3 * i + 2] = true;
            }
        }
        let mut soft_dofs = vec![false; 3 * nn];
        for d in 0..3 * nn {
            if pinned[d] {
                match soft.get(d % 3) {
                    Some(true) => soft_dofs[d] = true,
                    _ => fixed[d] = true,
                }
            }
        }
        let mut plug_of = vec![None; nn];
        for (k, ring) in mesh.plugs.iter().enumerate() {
            for &i in ring {
                fixed[3 * i] = true;
                fixed[3 * i + 1] = true;
                plug_of[i] = Some(k);
            }
        }
        let mut eq = vec![None; 3 * nn];
        let mut plug_eq = vec![None; mesh.plugs.len()];
        let mut n_eq = 0;
        for (d, f) in fixed.iter().enumerate() {
            if *f {
                continue;
            }
            match plug_of[d / 3] {
                Some(k) if d % 3 == 2 => {
                    eq[d] = Some(*plug_eq[k].get_or_insert_with(|| {
                        n_eq += 1;
                        n_eq - 1
                    }));
                }
                _ => {
                    eq[d] = Some(n_eq);
                    n_eq += 1;
                }
            }
        }
        let soft = (0..3 * nn)
            .filter(|&d| soft_dofs[d])
            .filter_map(|d| {
                eq[d].map(|e| SoftPin {
                    node: d / 3,
                    component: d % 3,
                    eq: e,
                    stiffness,
                })
            })
            .collect();
        Self {
            eq,
            n_eq,
            plug_eq,
            soft,
        }
    }

    /// The rigid-mode pins held by springs ([`DofMap::with_soft_pins`]).
    pub fn soft_pins(&self) -> &[SoftPin] {
        &self.soft
    }

    /// The number of equations.
    pub fn len(&self) -> usize {
        self.n_eq
    }

    pub fn is_empty(&self) -> bool {
        self.n_eq == 0
    }

    /// The equation of component `component` of node `node`, `None` where it is fixed.
    pub fn eq(&self, node: usize, component: usize) -> Option<usize> {
        self.eq[3 * node + component]
    }

    /// The equation of dof `d` = 3·node + component.
    pub fn eq_of_dof(&self, d: usize) -> Option<usize> {
        self.eq[d]
    }

    /// The axial equation of each plug.
    pub fn plug_equations(&self) -> &[Option<usize>] {
        &self.plug_eq
    }

    /// x ← x + t·dx on the free dofs.
    pub fn apply(&self, x: &mut [[f64; 3]], dx: &[f64], t: f64) {
        for (d, e) in self.eq.iter().enumerate() {
            if let Some(k) = e {
                x[d / 3][d % 3] += t * dx[*k];
            }
        }
    }

    /// x − x0 on the free dofs (a plug's shared axial equation takes any of its nodes' equal
    /// differences).
    pub fn difference(&self, x: &[[f64; 3]], x0: &[[f64; 3]]) -> Vec<f64> {
        let mut d = vec![0.0; self.n_eq];
        for (k, e) in self.eq.iter().enumerate() {
            if let Some(e) = e {
                d[*e] = x[k / 3][k % 3] - x0[k / 3][k % 3];
            }
        }
        d
    }

    /// The largest nodal displacement of an increment dx.
    pub fn max_nodal_norm(&self, dx: &[f64]) -> f64 {
        (0..self.eq.len() / 3)
            .map(|i| {
                (0..3)
                    .map(|k| self.eq[3 * i + k].map_or(0.0, |e| dx[e] * dx[e]))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max)
    }
}
