//! Batch scripts for clusters: a Slurm job array of shards with a dependent merge job, and the
//! Kubernetes equivalent (an Indexed Job and a merge Job).
//!
//! Every shard runs `clutchpack study run STUDY --out DIR --shard auto --shards N`; the array
//! index picks the shard (`SLURM_ARRAY_TASK_ID`, `JOB_COMPLETION_INDEX`), `N` is always
//! explicit. The scripts `exec` clutchpack, so that the scheduler's warning signal
//! (`--signal=B:TERM@S`: SIGTERM to the batch shell S seconds before the time limit) reaches
//! clutchpack itself, which stops starting cases, writes its part with the finished ones and
//! exits; a resubmission of the same index runs only the rest.

use std::fmt::Write as _;
use std::path::Path;

/// What the Slurm scripts need.
#[derive(Debug, Clone)]
pub struct SlurmJob<'a> {
    /// Job name prefix.
    pub name: &'a str,
    /// The clutchpack executable (absolute).
    pub exe: &'a Path,
    /// The study file (absolute).
    pub study: &'a Path,
    /// The output folder (absolute; on shared storage).
    pub out: &'a Path,
    /// Number of shards N.
    pub shards: u64,
    /// The array indexes to submit, in `--array` syntax (`0-3`, or `1,3` for a resubmission).
    pub array: String,
    /// `--time` of a shard (Slurm syntax).
    pub time: &'a str,
    /// `--time` of the merge job.
    pub merge_time: &'a str,
    /// `--partition`, if any.
    pub partition: Option<&'a str>,
    /// `--cpus-per-task` of a shard.
    pub cpus_per_task: u32,
    /// Seconds before the time limit at which a shard gets SIGTERM.
    pub signal_s: u32,
}

/// A value that cannot go into a generated script or manifest.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} {value:?}: {rule}")]
pub struct ScriptError {
    /// What the value is (`the output folder`, `--time`).
    pub what: String,
    /// The value.
    pub value: String,
    /// Why it is refused.
    pub rule: String,
}

/// The one shell quoting of every value a batch script holds: a word of safe characters as it
/// is, anything else in single quotes (`'` written as `'\''`). A control character (a line
/// break above all) is refused: on an `#SBATCH` line, which the shell reads as a comment and
/// Slurm parses itself, no quoting would stop a line break from starting a shell command.
pub fn sh_quote(what: &str, s: &str) -> Result<String, ScriptError> {
    if let Some(c) = s.chars().find(|c| c.is_control()) {
        return Err(ScriptError {
            what: what.to_string(),
            value: s.to_string(),
            rule: format!(
                "holds the control character {:?}; a batch script takes no control characters",
                c
            ),
        });
    }
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,@%".contains(c))
    {
        Ok(s.to_string())
    } else {
        Ok(format!("'{}'", s.replace('\'', "'\\''")))
    }
}

fn q(what: &str, p: &Path) -> Result<String, ScriptError> {
    sh_quote(what, &p.display().to_string())
}

/// The shard array's batch script; a value that cannot be quoted safely is an error naming it.
pub fn slurm_array_script(j: &SlurmJob) -> Result<String, ScriptError> {
    let mut s = String::from("#!/bin/bash\n");
    let logs = j.out.join("logs");
    let _ = writeln!(
        s,
        "#SBATCH --job-name={}",
        sh_quote("the study name", &format!("{}-shard", j.name))?
    );
    let _ = writeln!(s, "#SBATCH --array={}", sh_quote("--array", &j.array)?);
    let _ = writeln!(s, "#SBATCH --time={}", sh_quote("--time", j.time)?);
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", j.cpus_per_task);
    if let Some(p) = j.partition {
        let _ = writeln!(s, "#SBATCH --partition={}", sh_quote("--partition", p)?);
    }
    let _ = writeln!(
        s,
        "#SBATCH --output={}",
        q("the output folder", &logs.join("%x-%A_%a.out"))?
    );
    // SIGTERM to the batch shell (which exec makes clutchpack) before the time limit
    let _ = writeln!(s, "#SBATCH --signal=B:TERM@{}", j.signal_s);
    let _ = writeln!(s, "#SBATCH --chdir={}", q("the output folder", j.out)?);
    s.push_str("# One shard of the study per array task; clutchpack takes the shard index from\n");
    s.push_str("# SLURM_ARRAY_TASK_ID and its threads from SLURM_CPUS_PER_TASK.\n");
    let _ = writeln!(
        s,
        "exec {} study run {} --out {} --shard auto --shards {}",
        q("the clutchpack executable", j.exe)?,
        q("the study file", j.study)?,
        q("the output folder", j.out)?,
        j.shards
    );
    Ok(s)
}

/// The merge job's batch script (submitted with `--dependency=afterok:<array job>`).
pub fn slurm_merge_script(j: &SlurmJob) -> Result<String, ScriptError> {
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(
        s,
        "#SBATCH --job-name={}",
        sh_quote("the study name", &format!("{}-merge", j.name))?
    );
    let _ = writeln!(
        s,
        "#SBATCH --time={}",
        sh_quote("--merge-time", j.merge_time)?
    );
    let _ = writeln!(s, "#SBATCH --cpus-per-task=1");
    if let Some(p) = j.partition {
        let _ = writeln!(s, "#SBATCH --partition={}", sh_quote("--partition", p)?);
    }
    let _ = writeln!(
        s,
        "#SBATCH --output={}",
        q("the output folder", &j.out.join("logs").join("%x-%j.out"))?
    );
    let _ = writeln!(s, "#SBATCH --kill-on-invalid-dep=yes");
    let _ = writeln!(s, "#SBATCH --chdir={}", q("the output folder", j.out)?);
    let _ = writeln!(
        s,
        "exec {} study merge {}",
        q("the clutchpack executable", j.exe)?,
        q("the output folder", j.out)?
    );
    Ok(s)
}

/// The command lines that submit the two scripts (what `--dry-run` prints).
pub fn slurm_submit_commands(
    array_script: &Path,
    merge_script: &Path,
) -> Result<String, ScriptError> {
    Ok(format!(
        "aid=$(sbatch --parsable {})\naid=${{aid%%;*}}\nsbatch --parsable --dependency=afterok:$aid --kill-on-invalid-dep=yes {}\n",
        q("the shards script", array_script)?,
        q("the merge script", merge_script)?
    ))
}

/// What the Kubernetes manifests need.
#[derive(Debug, Clone)]
pub struct K8sJob<'a> {
    /// Job name prefix (a DNS label).
    pub name: &'a str,
    /// Container image with clutchpack on its PATH.
    pub image: &'a str,
    /// The study file's path inside the container (relative paths start at [`K8S_WORKDIR`]).
    pub study: &'a str,
    /// The output folder inside the container (relative paths start at [`K8S_WORKDIR`]).
    pub out: &'a str,
    /// Number of shards (completions).
    pub shards: u64,
    /// Pods at once.
    pub parallelism: u64,
    /// CPUs per pod.
    pub cpus: u32,
    /// The PersistentVolumeClaim (ReadWriteMany) mounted at [`K8S_WORKDIR`], the pods' working
    /// folder: it holds the study, its scene and the output folder.
    pub claim: &'a str,
}

/// Where the pods mount the claim, and their working folder.
pub const K8S_WORKDIR: &str = "/work";

/// A DNS-1123 label from `s`.
pub fn dns_label(s: &str) -> String {
    let mut l: String = s
        .to_ascii_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    l.truncate(50);
    let l = l.trim_matches('-').to_string();
    if l.is_empty() {
        "study".into()
    } else {
        l
    }
}

/// The pod template of both Jobs, as a serde value: every string the user gave (image, claim,
/// paths, name) is a JSON string written by serde_json, never text pasted into a manifest.
fn k8s_pod(j: &K8sJob, args: &[String], cpus: u32) -> serde_json::Value {
    serde_json::json!({
        "spec": {
            "restartPolicy": "Never",
            "containers": [{
                "name": "clutchpack",
                "image": j.image,
                "command": ["clutchpack"],
                "args": args,
                "workingDir": K8S_WORKDIR,
                "resources": {
                    "requests": { "cpu": cpus.to_string() },
                    "limits": { "cpu": cpus.to_string() },
                },
                "volumeMounts": [{ "name": "work", "mountPath": K8S_WORKDIR }],
            }],
            "volumes": [{
                "name": "work",
                "persistentVolumeClaim": { "claimName": j.claim },
            }],
        }
    })
}

/// A manifest as text: JSON, which is YAML (1.2 is a superset of JSON), so `kubectl apply -f`
/// reads it whatever the file's extension, and no value can break out of its string.
fn manifest(v: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(v).unwrap_or_default();
    s.push('\n');
    s
}

/// The Indexed Job of the shards: pod `i` runs shard `i` (`JOB_COMPLETION_INDEX`); a failed
/// pod is retried with the same index. A pod gets SIGTERM on deletion or eviction and
/// `terminationGracePeriodSeconds` to write its part.
pub fn k8s_indexed_job(j: &K8sJob) -> String {
    let args = [
        "study".to_string(),
        "run".into(),
        j.study.into(),
        "--out".into(),
        j.out.into(),
        "--shard".into(),
        "auto".into(),
        "--shards".into(),
        j.shards.to_string(),
    ];
    manifest(&serde_json::json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": format!("{}-shards", dns_label(j.name)) },
        "spec": {
            "completionMode": "Indexed",
            "completions": j.shards,
            "parallelism": j.parallelism,
            "backoffLimitPerIndex": 2,
            "template": k8s_pod(j, &args, j.cpus),
        }
    }))
}

/// The merge Job: start it once the shards' Job is `Complete`
/// (`kubectl wait --for=condition=complete job/<name>-shards`); Kubernetes has no dependency
/// between Jobs.
pub fn k8s_merge_job(j: &K8sJob) -> String {
    let args = ["study".to_string(), "merge".into(), j.out.into()];
    manifest(&serde_json::json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": format!("{}-merge", dns_label(j.name)) },
        "spec": {
            "backoffLimit": 1,
            "template": k8s_pod(j, &args, 1),
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_script_has_the_options_that_matter() {
        let j = SlurmJob {
            name: "mc",
            exe: Path::new("/opt/cp/clutchpack"),
            study: Path::new("/shared/s.toml"),
            out: Path::new("/shared/out dir"),
            shards: 4,
            array: "0-3".into(),
            time: "00:10:00",
            merge_time: "00:05:00",
            partition: Some("short"),
            cpus_per_task: 2,
            signal_s: 60,
        };
        let a = slurm_array_script(&j).unwrap();
        for want in [
            "#SBATCH --array=0-3",
            "#SBATCH --signal=B:TERM@60",
            "#SBATCH --output='/shared/out dir/logs/%x-%A_%a.out'",
            "#SBATCH --partition=short",
            "exec /opt/cp/clutchpack study run /shared/s.toml --out '/shared/out dir' --shard auto --shards 4",
        ] {
            assert!(a.contains(want), "{want} not in\n{a}");
        }
        let m = slurm_merge_script(&j).unwrap();
        assert!(m.contains("--kill-on-invalid-dep=yes") && m.contains("study merge"));
        let c = slurm_submit_commands(Path::new("/a.sh"), Path::new("/m.sh")).unwrap();
        assert!(c.contains("--dependency=afterok:$aid"));
        let k = k8s_indexed_job(&K8sJob {
            name: "MC study",
            image: "img",
            study: "/work/s.toml",
            out: "/work/out",
            shards: 8,
            parallelism: 4,
            cpus: 2,
            claim: "pvc",
        });
        let k: serde_json::Value = serde_json::from_str(&k).unwrap();
        assert_eq!(k["spec"]["completionMode"], "Indexed");
        assert_eq!(k["spec"]["completions"], 8);
        assert_eq!(k["metadata"]["name"], "mc-study-shards");
        let c = &k["spec"]["template"]["spec"]["containers"][0];
        assert_eq!(c["workingDir"], "/work");
        assert_eq!(c["volumeMounts"][0]["mountPath"], "/work");
    }

    /// Strings of every character class a path or name could hold: shell metacharacters,
    /// quotes, globs, spaces, non-ASCII, a leading dash, YAML and JSON syntax; and control
    /// characters, which the quoting refuses.
    fn hostile_strings() -> Vec<String> {
        let mut v: Vec<String> = (0x20u8..0x7f).map(|c| format!("a{}b", c as char)).collect();
        v.extend(
            [
                "",
                " ",
                "'",
                "''",
                "\"",
                "'\\''",
                "$(touch PWNED)",
                "`touch PWNED`",
                "${HOME}",
                "a; touch PWNED",
                "a && touch PWNED",
                "a | tee x",
                "*",
                "?[a]",
                "~root",
                "-rf",
                "--evil",
                "a\", \"--evil",
                "key: value",
                "- item",
                "{a: [1, 2]}",
                "&anchor *alias !tag %YAML #comment",
                "café 日本 🚀",
                "\u{a0}\u{2028}\u{feff}",
                "back\\slash\\",
                "/some/other/dir/evil",
            ]
            .iter()
            .map(|s| s.to_string()),
        );
        for c in ['\n', '\r', '\t', '\0', '\u{7f}', '\u{1b}', '\u{85}'] {
            v.push(format!("x{c}touch PWNED{c}#"));
        }
        v
    }

    /// Every hostile string either is refused (exactly those holding a control character) or
    /// comes back byte for byte from bash, as one word.
    #[test]
    fn shell_quoting_round_trips_every_character_class_or_refuses_it() {
        let strings = hostile_strings();
        let mut script = String::from("printf '%s\\0'");
        let mut kept = Vec::new();
        for s in &strings {
            match sh_quote("a value", s) {
                Ok(q) => {
                    script.push(' ');
                    script.push_str(&q);
                    kept.push(s.clone());
                }
                Err(e) => {
                    assert!(s.chars().any(|c| c.is_control()), "{s:?} refused: {e}");
                    assert!(e.to_string().contains("control character"), "{e}");
                }
            }
        }
        assert_eq!(
            kept.len(),
            strings.len() - 7,
            "only the control characters are refused"
        );
        let dir = std::env::temp_dir().join(format!("cp-quote-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let o = std::process::Command::new("bash")
            .arg("-c")
            .arg(&script)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let got: Vec<String> = o
            .stdout
            .split(|b| *b == 0)
            .map(|w| String::from_utf8(w.to_vec()).unwrap())
            .collect();
        // printf ends every word with NUL: one empty piece after the last
        assert_eq!(&got[..got.len() - 1], &kept[..]);
        assert!(!dir.join("PWNED").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The shards and merge scripts with every hostile string as the study, the output folder
    /// and the partition: each passes `bash -n`, and run by bash (as sbatch does) with a stand-in
    /// executable it hands clutchpack exactly the study and folder it was given; names with a
    /// control character are refused. No file is created by the script itself.
    #[test]
    fn batch_scripts_parse_and_pass_every_value_as_one_word() {
        let dir = std::env::temp_dir().join(format!("cp-scripts-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let exe = dir.join("echo args");
        std::fs::write(&exe, "#!/bin/sh\nprintf '%s\\0' \"$@\"\n").unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
        for s in hostile_strings() {
            let (study, out) = (dir.join(format!("{s}.toml")), dir.join(&s));
            let j = SlurmJob {
                name: &s,
                exe: &exe,
                study: &study,
                out: &out,
                shards: 2,
                array: "0-1".into(),
                time: "00:10:00",
                merge_time: "00:05:00",
                partition: Some(&s),
                cpus_per_task: 1,
                signal_s: 60,
            };
            let (a, m) = match (slurm_array_script(&j), slurm_merge_script(&j)) {
                (Ok(a), Ok(m)) => (a, m),
                (a, m) => {
                    assert!(s.chars().any(|c| c.is_control()), "{s:?}: {a:?} {m:?}");
                    continue;
                }
            };
            for script in [&a, &m] {
                let n = std::process::Command::new("bash")
                    .args(["-n", "-c", script])
                    .output()
                    .unwrap();
                assert!(n.status.success(), "bash -n on {s:?}:\n{script}");
                // every #SBATCH line stays one comment line
                assert!(script
                    .lines()
                    .all(|l| l.starts_with('#') || l.starts_with("exec ")));
            }
            let o = std::process::Command::new("bash")
                .arg("-c")
                .arg(&a)
                .current_dir(&dir)
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "{s:?}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let words: Vec<String> = o
                .stdout
                .split(|b| *b == 0)
                .map(|w| String::from_utf8(w.to_vec()).unwrap())
                .collect();
            let want = [
                "study",
                "run",
                &study.display().to_string(),
                "--out",
                &out.display().to_string(),
                "--shard",
                "auto",
                "--shards",
                "2",
                "",
            ]
            .map(String::from);
            assert_eq!(words, want, "{s:?}");
        }
        let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(left.len(), 1, "only the stand-in executable: {left:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The Kubernetes manifests with every hostile string as the name, the image, the claim,
    /// the study and the folder, read back by a YAML parser: one document each, the values
    /// where they were put, byte for byte, and the name a DNS label.
    #[test]
    fn manifests_read_back_by_a_yaml_parser_hold_every_value_as_given() {
        use yaml_rust2::YamlLoader;
        for s in hostile_strings() {
            let j = K8sJob {
                name: &s,
                image: &s,
                study: &s,
                out: &s,
                shards: 3,
                parallelism: 3,
                cpus: 2,
                claim: &s,
            };
            for (text, args) in [
                (
                    k8s_indexed_job(&j),
                    vec![
                        "study", "run", &s, "--out", &s, "--shard", "auto", "--shards", "3",
                    ],
                ),
                (k8s_merge_job(&j), vec!["study", "merge", &s]),
            ] {
                let docs = YamlLoader::load_from_str(&text)
                    .unwrap_or_else(|e| panic!("{s:?}: {e}\n{text}"));
                assert_eq!(docs.len(), 1, "{s:?}");
                let d = &docs[0];
                let c = &d["spec"]["template"]["spec"]["containers"][0];
                let got: Vec<&str> = c["args"]
                    .as_vec()
                    .unwrap()
                    .iter()
                    .map(|a| a.as_str().unwrap())
                    .collect();
                assert_eq!(got, args, "{s:?}");
                assert_eq!(c["image"].as_str(), Some(s.as_str()));
                let claim = &d["spec"]["template"]["spec"]["volumes"][0]["persistentVolumeClaim"];
                assert_eq!(claim["claimName"].as_str(), Some(s.as_str()));
                let name = d["metadata"]["name"].as_str().unwrap();
                assert!(
                    name.len() <= 63
                        && name
                            .chars()
                            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
                        && !name.starts_with('-'),
                    "{name:?}"
                );
            }
        }
    }
}
