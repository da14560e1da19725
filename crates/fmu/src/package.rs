//! The `.fmu` archive of a scene: the model description, the binary (this crate built as a
//! cdylib) and the scene as resources.

use crate::description::{model_description, Header, MODEL_IDENTIFIER};
use clutchpack_sdk::cosim::variables;
use clutchpack_sdk::model::session::Driven;
use clutchpack_sdk::scene::{EngineChoice, Scene};
use clutchpack_sdk::{SessionRequest, Simulation};
use std::hash::{Hash, Hasher};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Why an FMU could not be built.
#[derive(Debug, thiserror::Error)]
pub enum PackageError {
    /// The scene cannot be co-simulated (its engine cannot start a session on it).
    #[error("{0}")]
    Unrepresentable(String),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

/// The communication step of the model description's default experiment, s.
pub const DEFAULT_STEP_S: f64 = 1e-5;
/// The communication step of a network scene's default experiment, s.
pub const NETWORK_STEP_S: f64 = 1e-3;

/// Whether `scene` can be an FMU with `engine` (`None`: the scene's choice): the engine must
/// start a session driving every input the pack has. The error says why not.
pub fn check_representable(
    scene: &Scene,
    engine: Option<EngineChoice>,
) -> Result<EngineChoice, PackageError> {
    if let Some(net) = &scene.network {
        if let Some(why) = clutchpack_sdk::network_name_problems(net).first() {
            return Err(PackageError::Unrepresentable(format!(
                "{}: {why}",
                scene.name
            )));
        }
        // a network drives every input it has: a run of it must start so
        let names: Vec<String> = clutchpack_sdk::network_inputs(net)
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        let sim = clutchpack_sdk::NetworkSimulation::start(scene, engine, &names, None, None)
            .map_err(|e| PackageError::Unrepresentable(e.to_string()))?;
        return Ok(sim.engine());
    }
    let sim = Simulation::new(scene.clone(), engine)
        .map_err(|e| PackageError::Unrepresentable(e.to_string()))?;
    sim.start(SessionRequest {
        driven: Driven::all_for(&scene.pack),
        ..SessionRequest::default()
    })
    .map_err(|e| {
        PackageError::Unrepresentable(format!(
            "{}: the {} engine cannot run it as a co-simulation: {e}",
            scene.name,
            sim.engine_name()
        ))
    })?;
    Ok(EngineChoice::from_name(sim.engine_name()).expect("an engine's own name"))
}

/// The GUID of an FMU of `scene_json` (a hash of it and of this crate's version): the
/// binary checks the packed scene against it at `fmi2Instantiate`.
pub(crate) fn guid(scene_json: &str) -> String {
    let part = |seed: &str| {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (seed, env!("CARGO_PKG_VERSION"), scene_json).hash(&mut h);
        h.finish()
    };
    let (a, b) = (part("clutchpack-fmu-a"), part("clutchpack-fmu-b"));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

/// Writes the FMU of `scene` run by `engine` to `out` (atomically: a temporary sibling
/// renamed into place), with the binary `library` (`libclutchpack_fmu.so`). Returns the
/// number of variables.
pub fn write_fmu(
    scene: &Scene,
    engine: EngineChoice,
    library: &Path,
    out: &Path,
) -> Result<usize, PackageError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| PackageError::Io { path, source }
    };
    let binary = std::fs::read(library).map_err(io(library))?;
    // the engine travels in the scene: the binary's default is the description's start value
    let mut scene = scene.clone();
    scene.simulation.engine = Some(engine);
    let scene = &scene;
    let scene_json = serde_json::to_string_pretty(scene).expect("a scene serialises");
    let guid = guid(&scene_json);
    let vars = variables(scene, engine.name(), Driven::all_for(&scene.pack));
    let xml = model_description(
        &Header {
            model_name: &scene.name,
            description: &scene.description,
            guid: &guid,
            stop_time_s: scene.simulation.duration_s,
            // a network's default experiment steps at its sample interval (its events are
            // located inside the steps, its inputs take no slopes)
            step_s: if scene.network.is_some() {
                NETWORK_STEP_S
            } else {
                DEFAULT_STEP_S
            },
            interpolates_inputs: scene.network.is_none(),
        },
        &vars,
    );
    let (pending, file) =
        clutchpack_sdk::record::PendingFile::create(out, clutchpack_sdk::record::Replace::Existing)
            .map_err(io(out))?;
    let mut zip = zip::ZipWriter::new(file);
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let mut entries: Vec<(String, &[u8], u32)> = vec![
        ("modelDescription.xml".into(), xml.as_bytes(), 0o644),
        (
            format!("binaries/linux64/{MODEL_IDENTIFIER}.so"),
            &binary,
            0o755,
        ),
        ("resources/scene.json".into(), scene_json.as_bytes(), 0o644),
        ("resources/guid.txt".into(), guid.as_bytes(), 0o644),
    ];
    if !scene.source_text.is_empty() {
        entries.push((
            "resources/scene.toml".into(),
            scene.source_text.as_bytes(),
            0o644,
        ));
    }
    let zipped = |e: zip::result::ZipError| std::io::Error::other(e.to_string());
    for (name, bytes, mode) in entries {
        zip.start_file(name, deflated.unix_permissions(mode))
            .map_err(zipped)
            .map_err(io(out))?;
        zip.write_all(bytes).map_err(io(out))?;
    }
    let file = zip.finish().map_err(zipped).map_err(io(out))?;
    file.sync_all().map_err(io(out))?;
    drop(file);
    pending.commit().map_err(io(out))?;
    Ok(vars.len())
}

#[cfg(test)]
mod tests {
    use super::guid;

    #[test]
    fn the_guid_follows_the_scene() {
        let (a, b) = (guid("{\"name\": \"a\"}"), guid("{\"name\": \"b\"}"));
        assert_ne!(a, b);
        assert_eq!(a, guid("{\"name\": \"a\"}"));
        assert_eq!(a.len(), 38, "{a}");
    }
}
