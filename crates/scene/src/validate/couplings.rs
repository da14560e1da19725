//! `[[couplings]]` of a one-pack scene (no `[[bodies]]`): couplings between two of the pack's
//! rotating bodies besides the splines and the stack (MODEL.md section 8; the one kind a pack
//! takes so far: a torsional spring-damper between the shaft and the drum), each checked
//! against the bodies the scene has. A network scene's couplings are `network.rs`'s.

use super::Checker;
use crate::keys::RawCoupling as C;
use crate::schema::{show, Key, RawTable};
use clutchpack_model::{PackBody, PackCoupling, PackCouplingKind, SpringDamper};

/// What a `kind` names (the order of the key's choices).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// A kind of a network only (a clutch, an ideal gear, a gear mesh, a resolved pack).
    Network,
    SpringDamper,
}

/// The bodies a coupling of a one-pack scene can name, with their model values.
const BODIES: [(&str, PackBody); 2] = [("shaft", PackBody::Shaft), ("drum", PackBody::Drum)];

/// The keys of the network's kinds, refused in a spring-damper's entry.
const OTHER_KEYS: [&Key; 14] = [
    &C::ratio,
    &C::mu,
    &C::mu_speeds_rad_s,
    &C::mu_values,
    &C::peak,
    &C::cgeo_m,
    &C::max_normal_force_n,
    &C::base_radius_a_m,
    &C::base_radius_b_m,
    &C::internal,
    &C::backlash_m,
    &C::pairs,
    &C::mesh_offset_m,
    &C::pack,
];

/// The path of key `k` of entry `i`: `couplings[2].b`.
fn item(k: &Key, i: usize) -> String {
    k.at(&format!("couplings[{i}]"))
}

/// Every `[[couplings]]` entry of a one-pack scene (none: an empty list); `has_drum`: whether
/// the scene has a `[drum]`. A coupling joins two different bodies; a prescribed shaft may be
/// one of them (it then drives the other through the coupling, docs/DECISIONS.md "Couplings
/// between bodies").
pub(super) fn couplings(
    ck: &mut Checker,
    raw: Option<&[C]>,
    has_drum: bool,
) -> Option<Vec<PackCoupling>> {
    let mut out = Some(Vec::new());
    let mut names: Vec<String> = Vec::new();
    for (i, r) in raw.unwrap_or_default().iter().enumerate() {
        let c = coupling(ck, i, r, has_drum, &mut names);
        match (out.as_mut(), c) {
            (Some(o), Some(c)) => o.push(c),
            _ => out = None,
        }
    }
    out
}

/// Entry `i`; `names` the names of the entries before it (each unique).
fn coupling(
    ck: &mut Checker,
    i: usize,
    r: &C,
    has_drum: bool,
    names: &mut Vec<String>,
) -> Option<PackCoupling> {
    let path = |k: &Key| item(k, i);
    // the network's default name, `<kind>-<i+1>`
    let name = ck
        .text(&path(&C::name), r.value(&C::name))
        .or(format!("spring_damper-{}", i + 1));
    if let Some(n) = &name {
        if names.contains(n) {
            ck.report(
                path(&C::name),
                Some(format!("\"{n}\"")),
                "must be unique among the couplings",
            );
        }
        names.push(n.clone());
    }
    let kind = ck
        .choice(
            &path(&C::kind),
            r.value(&C::kind),
            &C::kind,
            &[
                Kind::Network,
                Kind::Network,
                Kind::Network,
                Kind::SpringDamper,
                Kind::Network,
                Kind::Network,
                Kind::Network,
                Kind::Network,
            ],
        )
        .required(ck, &path(&C::kind), "\"spring_damper\"");
    if kind == Some(Kind::Network) {
        ck.report(
            path(&C::kind),
            r.value(&C::kind).map(show),
            "a one-pack scene's couplings join its shaft and drum: only \"spring_damper\" \
             (the other kinds join the bodies of a network: [[bodies]])",
        );
        return None;
    }
    let a = body(ck, &path(&C::a), r.value(&C::a), has_drum);
    let b = body(ck, &path(&C::b), r.value(&C::b), has_drum);
    if let (Some(a), Some(b)) = (a, b) {
        if a == b {
            ck.report(
                path(&C::b),
                r.value(&C::b).map(show),
                "must name another body than a (a coupling joins two bodies)",
            );
            return None;
        }
    }
    kind?;
    for k in OTHER_KEYS {
        ck.not_allowed(
            &path(k),
            r.value(k),
            "a key of a network's couplings; remove it for kind = \"spring_damper\"",
        );
    }
    for (table, present) in [
        ("force", r.force.is_some()),
        ("contact", r.contact.is_some()),
        ("oil", r.oil.is_some()),
    ] {
        if present {
            ck.report(
                format!("couplings[{i}].{table}"),
                None,
                "a table of a network's couplings; remove it for kind = \"spring_damper\"",
            );
        }
    }
    let num = |ck: &mut Checker, k: &Key| ck.num(&path(k), r.value(k), k);
    let k = num(ck, &C::stiffness_n_m_per_rad).required(
        ck,
        &path(&C::stiffness_n_m_per_rad),
        "the spring's stiffness, N m/rad",
    );
    let d = num(ck, &C::damping_n_m_s_per_rad).or(C::damping_n_m_s_per_rad.default_num());
    let theta0 = num(ck, &C::free_angle_rad).or(C::free_angle_rad.default_num());
    name?;
    Some(PackCoupling {
        a: a?,
        b: b?,
        kind: PackCouplingKind::SpringDamper(SpringDamper {
            stiffness_n_m_per_rad: k?,
            damping_n_m_s_per_rad: d?,
            free_angle_rad: theta0?,
        }),
    })
}

/// A body name at `path`: one of [`BODIES`], the drum only with a `[drum]`.
fn body(ck: &mut Checker, path: &str, v: Option<&toml::Value>, has_drum: bool) -> Option<PackBody> {
    let name = ck
        .text(path, v)
        .required(ck, path, "\"shaft\" or \"drum\"")?;
    match BODIES.iter().find(|(n, _)| *n == name) {
        Some((_, PackBody::Drum)) if !has_drum => {
            ck.report(
                path,
                v.map(show),
                "the scene has no [drum]: add one (its inertia, load and drag) or couple \
                 another body",
            );
            None
        }
        Some(&(_, body)) => Some(body),
        None => {
            let names: Vec<String> = BODIES.iter().map(|(n, _)| format!("\"{n}\"")).collect();
            ck.report(
                path,
                v.map(show),
                format!(
                    "unknown body: must be one of {} (the bodies of a one-pack scene; a \
                     network names its [[bodies]])",
                    names.join(", ")
                ),
            );
            None
        }
    }
}
