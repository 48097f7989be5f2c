//! What the LAMMPS deck (version 20220106, Debian's `lmp`) says in its own words; the rest
//! of it is the LIGGGHTS deck's ([`super::liggghts`]), the same input language: grains,
//! rough rows, loads, stages and records.
//!
//! Model: `pair_style granular` with one `pair_coeff I J` for every pair of atom types
//! (LAMMPS would mix a pair it is not given from the two types' own, not as grainlab
//! mixes), each the pair's numbers as grainlab computes them:
//! - Hertz: `hertz KN D tangential mindlin KT X MU`, KN = 4/3 E*, KT = 8 G* (LAMMPS
//!   multiplies both by sqrt(R* dn)); the linear spring: `hooke KN D tangential
//!   linear_history KT X MU`, the derived spring's kn = kt from its (R*, m*), one per pair
//!   of types or refused by name;
//! - damping: `damping tsuji` damps a contact with `alpha(D) sqrt(m* k)`, k the secant
//!   normal stiffness (KN sqrt(R* dn) or KN), and alpha LAMMPS' polynomial of its input D
//!   ([`tsuji_alpha`]); grainlab's gn is that with alpha = sqrt(5) |beta(e)| (Hertz:
//!   2 sqrt(5/6) |beta| sqrt(Sn m*), Sn = 3/2 k) or 2 |beta(e)| (spring), so D is the root
//!   of the polynomial ([`tsuji_input`]); the tangential damping is X times the normal one,
//!   X = grainlab's gt / gn. At e = 1, `damping viscoelastic` with D = 0 (no damping: the
//!   polynomial's value at 1 is 3e-4, not 0);
//! - the clamp: `limit_damping` (the total normal force held at 0 or above);
//! - flat walls: `fix wall/gran granular` with the same words (R* = r, m* = m), one fix per
//!   material of the free grains, for the pair (wall material, grain material): a
//!   wall/gran fix has one set of coefficients.
//!
//! What differs by design (the deck's `# Differs:` lines, [`super::fields`]): LAMMPS'
//! tangential history caps the total tangential force, damping included, and rescales the
//! history when a pair's contact frame turns; its lever arms are r in the contact velocity
//! and r - dn/2 in a pair's torque (r on a wall).

use std::fmt::Write as _;

use super::common::{Code, ContactKinds, contact_kinds, f};
use super::fields::refuse;
use super::prepare::Exported;
use crate::error::Error;
use crate::physics::material::PairMaterial;
use crate::scene::{DampingSpec, NormalLaw, Scene, TangentialSpec};

pub use crate::physics::contact::damping::tsuji_alpha;

/// The input c for which LAMMPS' Tsuji polynomial gives `alpha` (> 0). The polynomial
/// falls monotonically on [-1, 1.1] from 89.1 to -0.05 (tested), and below -1 too (every
/// term then grows as c falls), so every alpha has one root, found by bisection to the
/// last bit (the bracket widened below -1 for the clamped damping's large alphas). LAMMPS
/// does not clip c to [0, 1]: e below about 0.11 needs c < 0, e above 0.9995 c > 1.
pub fn tsuji_input(alpha: f64) -> f64 {
    let (mut lo, mut hi) = (-1.0_f64, 1.1_f64);
    while tsuji_alpha(lo) <= alpha && lo > -1e6 {
        (hi, lo) = (lo, 2.0 * lo);
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if tsuji_alpha(mid) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // The closer of the two bracketing inputs.
    if (tsuji_alpha(lo) - alpha).abs() <= (tsuji_alpha(hi) - alpha).abs() { lo } else { hi }
}

/// The kinds of contact the LAMMPS deck tells apart: by the derived spring's kn (LAMMPS
/// takes one per pair of types and per wall fix); under the other laws every contact of a
/// pair of types takes the same words.
pub(crate) fn kinds<D: crate::physics::dim::Dim>(scene: &Scene, ex: &Exported<D>) -> ContactKinds {
    let e = ex.built.engine.as_ref();
    let mats = &scene.materials;
    let derived = matches!(scene.model.normal, NormalLaw::Hooke { .. });
    contact_kinds(mats.len(), e.particles(), e.walls(), |a, b, m, r| {
        if derived { scene.model.normal.stiffness(&PairMaterial::mix(&mats[a], &mats[b]), r, m, 0.0).kn } else { 0.0 }
    })
}

/// The contact model words of a pair of materials `pm` whose contacts have the keys `kns`
/// of [`kinds`] (the derived spring's kn, one or refused; `what` names the pair in a
/// refusal).
fn words(scene: &Scene, pm: &PairMaterial, kns: &[f64], what: &str) -> Result<String, Error> {
    let model = &scene.model;
    let mu = if model.tangential == TangentialSpec::Frictionless { 0.0 } else { pm.friction };
    // The normal words, the tangential stiffness and model, and the damping's alpha and
    // tangential-to-normal ratio (grainlab's gt / gn).
    let beta = pm.beta.abs();
    let (normal, kt, tangential, alpha, ratio) = match model.normal {
        NormalLaw::Hertz => {
            let ratio = if pm.viscous_n != 0.0 { pm.viscous_t / pm.viscous_n } else { (4.0 * pm.g_star / pm.e_star).sqrt() };
            (("hertz", 4.0 / 3.0 * pm.e_star), 8.0 * pm.g_star, "mindlin", 5f64.sqrt() * beta, ratio)
        }
        NormalLaw::HookeStiffness { kn, kt } => (("hooke", kn), kt, "linear_history", 2.0 * beta, (kt / kn).sqrt()),
        NormalLaw::Hooke { characteristic_velocity } => {
            // One kn for every contact of the pair (a pair that never meets takes any
            // value: its coefficients are never used).
            if let [k0, k1, ..] = kns {
                return Err(refuse(Code::Lammps, "model.normal.hooke.characteristic_velocity", characteristic_velocity, &format!("{what} meet at kn = {k0:e} N/m and {k1:e} N/m")));
            }
            let kn = kns.first().copied().unwrap_or(1.0);
            (("hooke", kn), kn, "linear_history", 2.0 * beta, 1.0)
        }
    };
    let (damping, d, ratio) = if scene.model.damping == DampingSpec::Tsuji {
        // grainlab's Tsuji damping is LAMMPS' own: the restitution is its input, and the
        // tangential damping alpha sqrt(m* kt) is sqrt(kt / kn) times the normal one.
        ("tsuji", pm.restitution, (kt / normal.1).sqrt())
    } else if scene.model.damping == DampingSpec::TsujiSqrt2 {
        // LAMMPS' current Tsuji damping, sqrt(2) alpha(e), in 20220106's `damping tsuji`:
        // the input whose fit gives that alpha (as the restitution damping's remap).
        ("tsuji", tsuji_input(tsuji_alpha(pm.restitution) * std::f64::consts::SQRT_2), (kt / normal.1).sqrt())
    } else if beta == 0.0 {
        ("viscoelastic", 0.0, ratio)
    } else {
        ("tsuji", tsuji_input(alpha), ratio)
    };
    // A ratio of two coefficients that underflowed to 0 (moduli near the smallest double):
    // both damping forces are then 0 in grainlab, and X times LAMMPS' 0 is 0 whatever X.
    let ratio = if ratio.is_finite() { ratio } else { 0.0 };
    let limit = if model.limit_force { " limit_damping" } else { "" };
    // DMT cohesion (Hertz only; prepare refused the spring): `dmt E D NU GAMMA`, from
    // which LAMMPS takes 4/3 E/(2(1 - NU^2)) between grains and 4/3 E/(2(1 - NU)) on a
    // wall: with NU = 0 and E = 2 E* both are KN; its attraction 4 pi GAMMA R* is
    // grainlab's 2 pi w R* with GAMMA = w/2.
    let normal = if pm.pulloff > 0.0 { format!("dmt {} {} 0 {}", f(2.0 * pm.e_star), f(d), f(pm.work_of_adhesion() / 2.0)) } else { format!("{} {} {}", normal.0, f(normal.1), f(d)) };
    // (prepare refused CDT and EPSD2)
    let rolling = match model.rolling {
        crate::scene::RollingSpec::Sds { stiffness, damping } => format!(" rolling sds {} {} {}", f(stiffness), f(damping), f(pm.rolling_friction)),
        _ => String::new(),
    };
    Ok(format!("{normal} tangential {tangential} {} {} {} damping {damping}{limit}{rolling}", f(kt), f(ratio), f(mu)))
}

/// `pair_style granular` and a `pair_coeff` for every pair of atom types.
pub(crate) fn pair_style(w: &mut String, scene: &Scene, kinds: &ContactKinds) -> Result<(), Error> {
    let mats = &scene.materials;
    let n = mats.len();
    let _ = writeln!(w, "# Each pair of atom types (materials) with grainlab's numbers: normal KN D, tangential KT X MU; D is the input of LAMMPS' Tsuji polynomial that gives grainlab's damping (docs/fidelity.md, LAMMPS).");
    let _ = writeln!(w, "pair_style granular");
    for a in 0..n {
        for b in a..n {
            let pm = PairMaterial::mix_with(&mats[a], &mats[b], scene.model.beta_rule());
            let model = words(scene, &pm, &kinds.pairs[a * n + b], &format!("materials[{a}] and materials[{b}]"))?;
            let _ = writeln!(w, "pair_coeff {} {} {model}", a + 1, b + 1);
        }
    }
    Ok(())
}

/// A flat wall: one `fix wall/gran granular` per material of the free grains, on the free
/// grains of that material, with the coefficients of the pair (wall material, grain
/// material); `plane` is its `yplane LO HI` and `shear x V` words.
pub(crate) fn flat_wall<D: crate::physics::dim::Dim>(w: &mut String, scene: &Scene, ex: &Exported<D>, kinds: &ContactKinds, index: usize, plane: &str) -> Result<(), Error> {
    let wall = &ex.built.engine.walls()[index];
    let mats = &scene.materials;
    let present: Vec<usize> = (0..mats.len()).filter(|&a| !kinds.walls[index][a].is_empty()).collect();
    for &a in &present {
        let pm = PairMaterial::mix_with(&mats[wall.material], &mats[a], scene.model.beta_rule());
        let model = words(scene, &pm, &kinds.walls[index][a], &format!("walls.{} and the free grains of materials[{a}]", wall.name))?;
        let group = if present.len() == 1 {
            "free".to_string()
        } else {
            let _ = writeln!(w, "group t{} type {}\ngroup free_t{} intersect free t{}", a + 1, a + 1, a + 1, a + 1);
            format!("free_t{}", a + 1)
        };
        let _ = writeln!(w, "fix w_{}_{} {group} wall/gran granular {model} {plane}", wall.name, a + 1);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_modulus_near_the_smallest_double_writes_finite_numbers() {
        // The fuzzer's case: a second material of E = 5e-324, whose mixed E* and G*
        // underflow, made the tangential damping ratio 0 / 0.
        let mut s = crate::scene::builtin::builtin("collision").unwrap();
        s.materials.push(crate::physics::material::Material { youngs_modulus: 5e-324, ..s.materials[0].clone() });
        if let crate::scene::Grains::List(l) = &mut s.grains {
            l[1].material = 1;
        }
        for damping in [crate::scene::DampingSpec::Restitution, crate::scene::DampingSpec::Tsuji, crate::scene::DampingSpec::TsujiSqrt2] {
            s.model.damping = damping;
            let files = super::super::export_files(&s, Code::Lammps, false, &Default::default()).unwrap();
            assert!(!files[0].1.to_ascii_lowercase().contains("nan") && !files[0].1.contains("inf"), "{}", files[0].1);
        }
    }

    #[test]
    fn the_tsuji_polynomial_falls_over_the_bisection_interval() {
        // Monotonic on [-1, 1.1]: one root for every alpha in between.
        let mut last = f64::INFINITY;
        for k in 0..=21000 {
            let c = -1.0 + 2.1 * k as f64 / 21000.0;
            let a = tsuji_alpha(c);
            assert!(a < last, "not falling at {c}");
            last = a;
        }
        assert!(tsuji_alpha(-1.0) > 80.0 && tsuji_alpha(1.1) < 0.0);
    }

    #[test]
    fn the_remap_returns_grainlab_damping_to_rounding() {
        // Every restitution of the workbench and the ends: LAMMPS' alpha of the input is
        // sqrt(5) |beta(e)| (Hertz) and 2 |beta(e)| (spring) to 1e-14 absolute, the
        // rounding of a sum of terms up to 30 (relative 1e-13 at e = 0.5, 1e-9 at
        // e = 0.99999, where alpha is 7e-6).
        for e in [1e-3, 0.05, 0.1, 0.114, 0.3, 0.5, 0.7, 0.9, 0.99, 0.9995, 0.99999] {
            let beta = crate::physics::material::beta(e).abs();
            for alpha in [5f64.sqrt() * beta, 2.0 * beta] {
                let c = tsuji_input(alpha);
                assert!((tsuji_alpha(c) - alpha).abs() <= 1e-14, "e = {e}: alpha {alpha}, c {c}, back {}", tsuji_alpha(c));
            }
        }
        // The notes' example: e = 0.5 needs 0.36665136 (Hertz).
        let c = tsuji_input(5f64.sqrt() * crate::physics::material::beta(0.5).abs());
        assert!((c - 0.36665136).abs() < 1e-8, "{c}");
        // LAMMPS' current Tsuji damping ("tsuji_sqrt2"), sqrt(2) alpha(e), in 20220106's
        // fit: the same rounding.
        for e in [1e-3, 0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 1.0] {
            let alpha = tsuji_alpha(e) * std::f64::consts::SQRT_2;
            let c = tsuji_input(alpha);
            assert!((tsuji_alpha(c) - alpha).abs() <= 1e-14, "e = {e}: alpha {alpha}, c {c}, back {}", tsuji_alpha(c));
        }
    }
}
