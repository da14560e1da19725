//! Issue 48, items 11 and 12 through the binary: messages that name what they mean in a few
//! characters, and a killed network recording that keeps what its run had done. Each test
//! is named after the defect it fixes (the reproducers).

use super::{bin, run, scratch, stderr, stdout};
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

fn repo(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(p)
        .display()
        .to_string()
}

/// Item 11: a gear ratio of 1e300 whose speeds do not mesh is refused with a line of about
/// 160 characters naming the key (it was 453 with the 303-digit speed `ratio x w_b`); every
/// number in it as `clutchpack check` echoes values (`fmt_num`: `8.571428571428571e301`).
/// The bound: 250 characters, well under the 453 of before.
#[test]
fn a_meshing_error_prints_its_speeds_short() {
    let d = scratch("msg-mesh");
    let text = std::fs::read_to_string(repo("scenes/dct-upshift-lumped.toml")).unwrap();
    let text = text.replacen("ratio = 3.5", "ratio = 1e300", 1);
    assert!(text.contains("ratio = 1e300"));
    std::fs::write(d.join("mesh.toml"), text).unwrap();
    std::fs::copy(
        repo("scenes/dct-upshift-k2.csv"),
        d.join("dct-upshift-k2.csv"),
    )
    .unwrap();
    let o = run(&["check", d.join("mesh.toml").to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("do not mesh"))
        .unwrap_or_else(|| panic!("no meshing error: {err}"));
    assert!(line.contains("couplings[3].ratio"), "{line}");
    assert!(line.ends_with("is 8.571428571428571e301"), "{line}");
    assert!(line.len() < 250, "{} characters: {line}", line.len());
}

/// Item 11: `study run --out` naming a file (or a folder under a file) says that the output
/// folder is a file, naming it, exit 2 before any case runs (it said "File exists (os error
/// 17)"), and leaves the file as it was.
#[test]
fn study_run_into_a_file_says_the_folder_is_a_file() {
    let d = scratch("msg-study-file");
    let study = super::study::small_study(&d, 0.01, 2);
    let file = d.join("out.txt");
    std::fs::write(&file, "mine").unwrap();
    for out in [file.clone(), file.join("deeper")] {
        let o = run(&[
            "study",
            "run",
            study.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("{} is a file, not a folder", file.display())),
            "{err}"
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
}

/// Item 12: `dct-upshift` killed (SIGKILL) some simulated seconds into a 60 s run: its
/// impacts, read back with `--salvage`, reach to within 0.1 s of its last sample (the
/// contacts of the locked packs, open since the shift, are logged every 0.05 s; before,
/// they ended at 2.33 s, where the last contact closed, with samples to 10 s and more), and
/// `compare --salvage` compares its packs' bodies (it said "nothing to compare").
#[test]
fn a_killed_network_recording_keeps_its_impacts_and_compares() {
    let d = scratch("killed-network");
    let out = d.join("k.mcap");
    let mut child = bin()
        .args([
            "run",
            "scenes/dct-upshift.toml",
            "--duration",
            "60",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // about 3 MB of recording per simulated second: killed past ~4 s (the last impact
    // closes at 2.33 s), whatever the machine's speed
    let t0 = Instant::now();
    let partial = loop {
        let found = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.to_string_lossy().contains(".partial-"));
        if let Some(p) = found.filter(|p| std::fs::metadata(p).unwrap().len() > 14 << 20) {
            break p;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before the kill"
        );
        assert!(t0.elapsed() < Duration::from_secs(300), "too slow");
        std::thread::sleep(Duration::from_millis(50));
    };
    child.kill().unwrap();
    child.wait().unwrap();
    let (reader, warning) = clutchpack_sdk::open_recording(&partial, true).unwrap();
    assert!(warning.is_some());
    let net = clutchpack_sdk::record::read_network(&reader)
        .unwrap()
        .unwrap();
    let last_sample = net.samples.last().unwrap().t_s;
    let last_impact = net
        .impacts
        .iter()
        .map(|(_, e)| e.t_off_s)
        .fold(0.0, f64::max);
    assert!(last_sample > 3.0, "killed at t = {last_sample} s");
    assert!(
        last_sample - last_impact < 0.1,
        "samples to {last_sample} s, impacts to {last_impact} s"
    );
    assert!(net.open_contacts > 0);
    let o = run(&[
        "compare",
        "--salvage",
        partial.to_str().unwrap(),
        partial.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = stdout(&o);
    assert!(table.contains("K2/"), "{table}");
    assert!(stderr(&o).contains("did not finish"), "{}", stderr(&o));
}
