//! `[transmission]` of a network scene (MODEL.md section 10): the input and output bodies and
//! the gears, each the set of shift elements closed in it; every gear's kinematics checked
//! (one degree of freedom left to the input, the output turning with it), every element
//! closed in some gear.

use super::Checker;
use crate::keys::{RawGear as G, RawTransmission as T};
use crate::schema::{Key, RawTable};
use clutchpack_model::network::{CouplingKind, Gear, Network, Transmission};

/// The transmission of `net` as `[transmission]` describes it, or `None` (each problem
/// reported at its key).
pub(super) fn transmission(ck: &mut Checker, raw: &T, net: &Network) -> Option<Transmission> {
    let body = |ck: &mut Checker, key: &Key| {
        let path = key.at("transmission");
        let name = ck.text(&path, raw.value(key)).required(
            ck,
            &path,
            "required: the name of a body in [[bodies]]",
        )?;
        let found = net.body_index(&name);
        if found.is_none() {
            ck.report(
                path,
                Some(format!("\"{name}\"")),
                "names no body in [[bodies]]",
            );
        }
        found
    };
    let (input, output) = (body(ck, &T::input), body(ck, &T::output));
    let raw_gears = raw.gears.as_deref().unwrap_or_default();
    if raw_gears.is_empty() {
        ck.report(
            "transmission.gears",
            None,
            "needs at least one [[transmission.gears]] entry",
        );
        return None;
    }
    let mut gears = Vec::new();
    let mut ok = true;
    for (i, g) in raw_gears.iter().enumerate() {
        let at = |key: &Key| format!("transmission.gears[{i}].{}", key.name);
        let name = ck.text(&at(&G::name), g.value(&G::name)).required(
            ck,
            &at(&G::name),
            "required: the gear's name",
        );
        if let Some(n) = &name {
            if gears.iter().any(|o: &Gear| &o.name == n) {
                ck.report(at(&G::name), Some(format!("\"{n}\"")), "names two gears");
                ok = false;
            }
        }
        let closed = ck.texts(&at(&G::closed), g.value(&G::closed)).required(
            ck,
            &at(&G::closed),
            "required: the elements closed in this gear",
        );
        let mut indices = Vec::new();
        for (j, e) in closed.iter().flatten().enumerate() {
            let path = format!("{}[{j}]", at(&G::closed));
            match net.couplings.iter().position(|c| &c.name == e) {
                Some(k) if matches!(net.couplings[k].kind, CouplingKind::Clutch(_)) => {
                    if indices.contains(&k) {
                        ck.report(
                            path,
                            Some(format!("\"{e}\"")),
                            "is named twice in this gear",
                        );
                        ok = false;
                    }
                    indices.push(k);
                }
                Some(_) => {
                    ck.report(
                        path,
                        Some(format!("\"{e}\"")),
                        "is not a shift element: a gear closes couplings of kind clutch or one_way_clutch",
                    );
                    ok = false;
                }
                None => {
                    ck.report(
                        path,
                        Some(format!("\"{e}\"")),
                        "names no coupling in [[couplings]]",
                    );
                    ok = false;
                }
            }
        }
        match (name, closed) {
            (Some(name), Some(_)) => gears.push(Gear {
                name,
                closed: indices,
            }),
            _ => ok = false,
        }
    }
    let tr = Transmission {
        input: input?,
        output: output?,
        gears,
    };
    if !ok {
        return None;
    }
    if tr.input == tr.output {
        ck.report(
            T::output.at("transmission"),
            None,
            "must be another body than the input",
        );
        return None;
    }
    for (i, g) in tr.gears.iter().enumerate() {
        if let Err(why) = tr.kinematics(net, i) {
            ck.report(
                format!("transmission.gears[{i}].{}", G::closed.name),
                None,
                format!("gear \"{}\" {why}", g.name),
            );
            ok = false;
        }
    }
    ok.then_some(tr)
}
