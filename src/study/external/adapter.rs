//! An adapter: a folder `<adapters>/<name>/` with a manifest `adapter.toml` that says how to
//! run one case of the case protocol, how to set the code up, and what the code supports.
//! Running one is a child process with a timeout; whatever goes wrong (no adapter, a set-up
//! that fails, a crash, a timeout) is an error string that becomes the case's failure.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// What a code supports, in igimp's names.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Supports {
    pub dimensions: Vec<usize>,
    /// Material models (registry names).
    pub models: Vec<String>,
    /// `gravity`, `displacement`, `traction`.
    pub loads: Vec<String>,
    /// Bases (igimp's method names); the first is the default.
    pub bases: Vec<String>,
}

/// `adapter.toml`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub name: String,
    pub summary: String,
    /// The protocol version the adapter speaks.
    pub protocol: u32,
    /// The argv of one case: `{case}` and `{result}` stand for the two files' paths, `{dir}`
    /// for the adapter's folder and `{study}` for the running `study` binary.
    pub command: Vec<String>,
    /// The argv run once per process before the adapter's first case (installs the code;
    /// must be quick when it is installed already).
    #[serde(default)]
    pub setup: Vec<String>,
    /// Most seconds one case may take (default 600).
    #[serde(default = "default_timeout")]
    pub timeout_seconds: f64,
    pub supports: Supports,
}

fn default_timeout() -> f64 {
    600.0
}

static ADAPTERS_DIR: OnceLock<PathBuf> = OnceLock::new();

/// Set the adapters folder for this process (`study --adapters`); the first call wins.
pub fn set_adapters_dir(dir: PathBuf) {
    let _ = ADAPTERS_DIR.set(dir);
}

/// The adapters folder: `--adapters`, else `IGIMP_ADAPTERS`, else `examples/adapters` in the
/// working directory, else the source tree's.
pub fn adapters_dir() -> PathBuf {
    if let Some(d) = ADAPTERS_DIR.get() {
        return d.clone();
    }
    if let Some(d) = std::env::var_os("IGIMP_ADAPTERS") {
        return PathBuf::from(d);
    }
    let local = PathBuf::from("examples/adapters");
    if local.is_dir() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adapters")
    }
}

/// An adapter found on disk.
#[derive(Debug, Clone)]
pub struct Adapter {
    pub dir: PathBuf,
    pub manifest: Manifest,
    /// The manifest's text (part of a case's hash: editing it re-runs the cases).
    pub text: String,
}

impl Adapter {
    /// The adapter `name` of the adapters folder.
    pub fn find(name: &str) -> Result<Adapter, String> {
        let dir = adapters_dir().join(name);
        let path = dir.join("adapter.toml");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("no adapter {name:?}: {}: {e}", path.display()))?;
        let manifest: Manifest = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if manifest.name != name {
            return Err(format!(
                "{}: `name` is {:?}, must be its folder's name {name:?}",
                path.display(),
                manifest.name
            ));
        }
        if manifest.protocol != super::protocol::VERSION {
            return Err(format!(
                "{}: `protocol` = {}, this harness speaks version {}",
                path.display(),
                manifest.protocol,
                super::protocol::VERSION
            ));
        }
        if manifest.command.is_empty() {
            return Err(format!("{}: `command` must not be empty", path.display()));
        }
        if !(manifest.timeout_seconds.is_finite() && manifest.timeout_seconds > 0.0) {
            return Err(format!(
                "{}: `timeout_seconds` must be finite and > 0",
                path.display()
            ));
        }
        let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
        Ok(Adapter { dir, manifest, text })
    }

    fn argv(&self, args: &[String], case: &Path, result: &Path) -> Vec<String> {
        let study = std::env::current_exe().map_or("study".into(), |p| p.display().to_string());
        args.iter()
            .map(|a| {
                a.replace("{case}", &case.display().to_string())
                    .replace("{result}", &result.display().to_string())
                    .replace("{dir}", &self.dir.display().to_string())
                    .replace("{study}", &study)
            })
            .collect()
    }

    /// Run the set-up command once per process (later calls return the first's outcome).
    pub fn set_up(&self) -> Result<(), String> {
        static DONE: OnceLock<Mutex<BTreeMap<String, Result<(), String>>>> = OnceLock::new();
        let done = DONE.get_or_init(Default::default);
        let mut done = done.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = done.get(&self.manifest.name) {
            return r.clone();
        }
        let r = if self.manifest.setup.is_empty() {
            Ok(())
        } else {
            let log = std::env::temp_dir().join(format!(
                "igimp-setup-{}-{}.log",
                self.manifest.name,
                std::process::id()
            ));
            let argv = self.argv(&self.manifest.setup, Path::new(""), Path::new(""));
            run(&argv, &self.dir, &log, Duration::from_secs(1800))
                .map_err(|e| format!("the set-up of adapter {:?} failed: {e}", self.manifest.name))
        };
        done.insert(self.manifest.name.clone(), r.clone());
        r
    }

    /// Run one case: `case` written, `result` to be written, the adapter's output in `log`.
    /// Returns the wall seconds of the process.
    pub fn run_case(&self, case: &Path, result: &Path, log: &Path) -> Result<f64, String> {
        let argv = self.argv(&self.manifest.command, case, result);
        let t = Instant::now();
        run(
            &argv,
            &self.dir,
            log,
            Duration::from_secs_f64(self.manifest.timeout_seconds),
        )?;
        Ok(t.elapsed().as_secs_f64())
    }
}

/// The last `lines` lines of the file at `path`.
pub fn tail(path: &Path, lines: usize) -> String {
    let mut text = String::new();
    if let Ok(mut f) = std::fs::File::open(path) {
        let _ = f.read_to_string(&mut text);
    }
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

/// Run `argv` in `dir` with stdout and stderr to `log`, killing its process group after
/// `timeout`.
fn run(argv: &[String], dir: &Path, log: &Path, timeout: Duration) -> Result<(), String> {
    let out = std::fs::File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let err = out.try_clone().map_err(|e| format!("{}: {e}", log.display()))?;
    let mut cmd = Command::new(&argv[0]);
    cmd.args(&argv[1..])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err);
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("could not start {:?}: {e}", argv[0]))?;
    let t = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if t.elapsed() > timeout => {
                // The whole group: a script's own children (a Python under a shell) too. The
                // child leads its own group (process_group(0) above), so its pid is the
                // group's id; the check keeps a bad id from ever naming another group.
                #[cfg(unix)]
                if let Ok(pgid) = libc::pid_t::try_from(child.id()) {
                    if pgid > 1 {
                        // SAFETY: killpg has no memory effects; it signals the group `pgid`.
                        unsafe {
                            libc::killpg(pgid, libc::SIGKILL);
                        }
                    }
                }
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!(
                    "timed out after {:.0} s (the manifest's timeout_seconds); its output ends:\n{}",
                    timeout.as_secs_f64(),
                    tail(log, 20)
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => return Err(format!("waiting for {:?}: {e}", argv[0])),
        }
    };
    if !status.success() {
        return Err(format!(
            "{:?} exited with {status}; its output ends:\n{}",
            argv[0],
            tail(log, 20)
        ));
    }
    Ok(())
}
