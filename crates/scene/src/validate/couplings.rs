//! `[[couplings]]`: couplings between two of the pack's rotating bodies besides the splines and
//! the stack (MODEL.md section 8; the one kind so far: a torsional spring-damper between the
//! shaft and the drum), each checked against the bodies the scene has.

use super::Checker;
use crate::keys::RawCoupling as C;
use crate::schema::{show, Key, RawTable};
use clutchpack_model::{CouplingKind, PackBody, PackCoupling, SpringDamper};

/// What a `kind` names (the order of the key's choices).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    SpringDamper,
}

/// The bodies a coupling of a one-pack scene can name, with their model values.
const BODIES: [(&str, PackBody); 2] = [("shaft", PackBody::Shaft), ("drum", PackBody::Drum)];

/// Every `[[couplings]]` entry (none: an empty list); `has_drum`: whether the scene has a
/// `[drum]`. A coupling joins two different bodies; a prescribed shaft may be one of them (it
/// then drives the other through the coupling, docs/DECISIONS.md "Couplings").
pub(super) fn couplings(
    ck: &mut Checker,
    raw: Option<&[C]>,
    has_drum: bool,
) -> Option<Vec<PackCoupling>> {
    let mut out = Some(Vec::new());
    for (i, r) in raw.unwrap_or_default().iter().enumerate() {
        let item = format!("couplings[{i}]");
        let c = coupling(ck, &item, r, has_drum);
        match (out.as_mut(), c) {
            (Some(o), Some(c)) => o.push(c),
            _ => out = None,
        }
    }
    out
}

/// One entry, at `item` (`couplings[2]`).
fn coupling(ck: &mut Checker, item: &str, r: &C, has_drum: bool) -> Option<PackCoupling> {
    let path = |k: &Key| k.at(item);
    let kind = ck
        .choice(
            &path(&C::kind),
            r.value(&C::kind),
            &C::kind,
            &[Kind::SpringDamper],
        )
        .required(ck, &path(&C::kind), "\"spring_damper\"");
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
    let num = |ck: &mut Checker, k: &Key| ck.num(&path(k), r.value(k), k);
    let law = match kind? {
        Kind::SpringDamper => {
            let k = num(ck, &C::stiffness_n_m_per_rad).required(
                ck,
                &path(&C::stiffness_n_m_per_rad),
                "the spring's stiffness, N m/rad",
            );
            let d = num(ck, &C::damping_n_m_s_per_rad).or(C::damping_n_m_s_per_rad.default_num());
            let theta0 = num(ck, &C::free_angle_rad).or(C::free_angle_rad.default_num());
            CouplingKind::SpringDamper(SpringDamper {
                stiffness_n_m_per_rad: k?,
                damping_n_m_s_per_rad: d?,
                free_angle_rad: theta0?,
            })
        }
    };
    Some(PackCoupling {
        a: a?,
        b: b?,
        kind: law,
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
                    "unknown body: must be one of {} (the bodies of a one-pack scene)",
                    names.join(", ")
                ),
            );
            None
        }
    }
}
