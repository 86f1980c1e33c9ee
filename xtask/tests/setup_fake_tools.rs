//! `cargo xtask setup` (the install step `run`, `test` and `bench` begin
//! with) against fake rustup, apt-get, sudo and id: shell scripts in a
//! directory that is the whole PATH. They print on stdout as the real ones do
//! (apt-get update's 165 lines), log how they were called, and the fake
//! apt-get "installs" QEMU by writing a qemu-system-arm script. Nothing is
//! really installed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const RUSTUP: &str = r#"#!/bin/sh
echo "rustup $*" >> "$FAKE_LOG"
case "$1 $2" in
  "target list") echo x86_64-unknown-linux-gnu; for t in $FAKE_TARGETS; do echo "$t"; done ;;
  "target add") echo "info: downloading component 'rust-std' for '$3'" ;;
esac
"#;

const APT_GET: &str = r#"#!/bin/sh
echo "apt-get $*" >> "$FAKE_LOG"
case "$1 $2" in
  "--version "*) echo "apt 2.6.1 (amd64)" ;;
  "update "*) i=0; while [ $i -lt 165 ]; do echo "Get:$i http://mirror.invalid bookworm InRelease"; i=$((i+1)); done ;;
  "install -s") /bin/cat "$FAKE_PLAN" ;;
  "install -y")
    echo "Setting up qemu-system-arm (1:7.2+dfsg-7) ..."
    printf '#!/bin/sh\necho "QEMU emulator version 7.2.0"\n' > "$FAKE_DIR/qemu-system-arm"
    /bin/chmod +x "$FAKE_DIR/qemu-system-arm" ;;
esac
"#;

const SUDO: &str = r#"#!/bin/sh
echo "sudo $*" >> "$FAKE_LOG"
[ "$1" = "-n" ] && shift
[ "$1" = "true" ] && exit "$FAKE_SUDO_STATUS"
exec "$@"
"#;

const ID: &str = "#!/bin/sh\necho \"$FAKE_UID\"\n";

/// apt-get's simulation of a plan that removes nothing.
const CLEAN_PLAN: &str = "\
The following NEW packages will be installed:
  qemu-system-arm qemu-system-common qemu-system-data
0 upgraded, 3 newly installed, 0 to remove and 0 not upgraded.
Inst qemu-system-data (1:7.2+dfsg-7 Debian:12 [all])
Inst qemu-system-common (1:7.2+dfsg-7 Debian:12 [amd64])
Inst qemu-system-arm (1:7.2+dfsg-7 Debian:12 [amd64])
";

/// The plan the issue met: installing QEMU removes qemu-utils.
const REMOVING_PLAN: &str = "\
The following packages will be REMOVED:
  qemu-utils
The following NEW packages will be installed:
  qemu-system-arm
0 upgraded, 1 newly installed, 1 to remove and 0 not upgraded.
Remv qemu-utils [1:7.2+dfsg-7]
Inst qemu-system-arm (1:7.2+dfsg-7 Debian:12 [amd64])
";

const DOWNGRADING_PLAN: &str = "\
The following packages will be DOWNGRADED:
  libfdt1
0 upgraded, 1 newly installed, 1 downgraded, 0 to remove and 0 not upgraded.
Inst libfdt1 [1.7.0-1] (1.6.1-4 Debian:12 [amd64])
Inst qemu-system-arm (1:7.2+dfsg-7 Debian:12 [amd64])
";

/// A machine as the fakes present it.
struct Machine {
    uid: u32,
    /// `sudo -n true`'s exit status, or no sudo at all.
    sudo: Option<i32>,
    plan: &'static str,
    targets_installed: bool,
    qemu_installed: bool,
}

impl Machine {
    const ROOT_WITHOUT_ANYTHING: Machine = Machine {
        uid: 0,
        sudo: None,
        plan: CLEAN_PLAN,
        targets_installed: false,
        qemu_installed: false,
    };
}

/// What `xtask setup` did: its output, and the fakes' log of calls.
struct Run {
    output: Output,
    log: Vec<String>,
    qemu_installed: bool,
}

impl Run {
    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }
}

fn write_script(dir: &Path, name: &str, text: &str) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let status = Command::new("/bin/chmod")
        .arg("+x")
        .arg(&path)
        .status()
        .unwrap();
    assert!(status.success());
}

fn setup_on(machine: Machine, name: &str) -> Run {
    let dir: PathBuf =
        std::env::temp_dir().join(format!("xtask-fakes-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    write_script(&bin, "rustup", RUSTUP);
    write_script(&bin, "apt-get", APT_GET);
    write_script(&bin, "id", ID);
    if machine.sudo.is_some() {
        write_script(&bin, "sudo", SUDO);
    }
    if machine.qemu_installed {
        write_script(&bin, "qemu-system-arm", "#!/bin/sh\necho QEMU 7.2\n");
    }
    let plan = dir.join("plan.txt");
    std::fs::write(&plan, machine.plan).unwrap();
    let log = dir.join("calls.log");
    std::fs::write(&log, "").unwrap();
    let targets = if machine.targets_installed {
        "thumbv7em-none-eabihf thumbv6m-none-eabi"
    } else {
        ""
    };
    let output = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("setup")
        .env("PATH", &bin)
        .env("FAKE_LOG", &log)
        .env("FAKE_DIR", &bin)
        .env("FAKE_PLAN", &plan)
        .env("FAKE_UID", machine.uid.to_string())
        .env("FAKE_SUDO_STATUS", machine.sudo.unwrap_or(0).to_string())
        .env("FAKE_TARGETS", targets)
        .output()
        .unwrap();
    let run = Run {
        output,
        log: std::fs::read_to_string(&log)
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect(),
        qemu_installed: bin.join("qemu-system-arm").exists(),
    };
    std::fs::remove_dir_all(&dir).unwrap();
    run
}

/// Every install step's output goes to stderr, after a line saying what it
/// installs and why; stdout (where `cargo xtask run` prints the CSV) stays
/// empty although the installers wrote 170 lines to theirs.
#[test]
fn installs_say_what_and_why_first_and_keep_stdout_for_the_csv() {
    let run = setup_on(Machine::ROOT_WITHOUT_ANYTHING, "root");
    let stderr = run.stderr();
    assert!(run.output.status.success(), "{stderr}");
    assert!(run.qemu_installed);
    assert_eq!(String::from_utf8_lossy(&run.output.stdout), "");
    assert_eq!(
        run.log,
        [
            "rustup target list --installed",
            "rustup target add thumbv7em-none-eabihf thumbv6m-none-eabi",
            "apt-get --version",
            "apt-get update",
            "apt-get install -s --no-install-recommends qemu-system-arm",
            "apt-get install -y --no-install-recommends --no-remove qemu-system-arm",
        ]
    );
    // Each announcement, then the installer's own lines (now on stderr).
    let at = |s: &str| {
        stderr
            .find(s)
            .unwrap_or_else(|| panic!("{s:?} in\n{stderr}"))
    };
    assert!(
        at("thumbv7em-none-eabihf (the Cortex-M4F boards' firmware)")
            < at("info: downloading component")
    );
    assert!(at("Installing the Debian package qemu-system-arm") < at("Get:0 "));
    assert!(at("Get:164 ") < at("apt-get installs 3 package(s): qemu-system-data"));
    assert!(at("apt-get installs 3 package(s)") < at("Setting up qemu-system-arm"));
}

#[test]
fn an_install_that_would_remove_a_package_is_refused_with_the_command_to_run() {
    let machine = Machine {
        plan: REMOVING_PLAN,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "removal");
    let stderr = run.stderr();
    assert!(!run.output.status.success());
    assert!(!run.qemu_installed);
    assert_eq!(String::from_utf8_lossy(&run.output.stdout), "");
    assert!(
        stderr.contains(
            "xtask: installing qemu-system-arm would remove qemu-utils, and xtask never \
             removes or downgrades an installed package."
        ),
        "{stderr}"
    );
    assert!(stderr.contains("\n    apt-get install --no-install-recommends qemu-system-arm\n"));
    assert!(
        !run.log.iter().any(|l| l.contains("install -y")),
        "{:?}",
        run.log
    );
}

#[test]
fn an_install_that_would_downgrade_a_package_is_refused() {
    let machine = Machine {
        plan: DOWNGRADING_PLAN,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "downgrade");
    let stderr = run.stderr();
    assert!(!run.output.status.success());
    assert!(
        stderr.contains("installing qemu-system-arm would downgrade libfdt1,"),
        "{stderr}"
    );
    assert!(!run.log.iter().any(|l| l.contains("install -y")));
}

/// Not root: passwordless sudo is used; sudo that asks, or none, gives the
/// exact commands to run and runs no apt-get as root.
#[test]
fn without_root_sudo_is_used_or_the_command_to_run_is_printed() {
    let user = |sudo| Machine {
        uid: 1000,
        sudo,
        targets_installed: true,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(user(Some(0)), "sudo");
    assert!(run.output.status.success(), "{}", run.stderr());
    assert!(run.qemu_installed);
    assert!(run.log.contains(&"sudo -n apt-get update".to_string()));
    assert!(run.log.contains(
        &"sudo -n apt-get install -y --no-install-recommends --no-remove qemu-system-arm"
            .to_string()
    ));

    let install = "apt-get install --no-install-recommends --no-remove qemu-system-arm";
    for (sudo, name, expected) in [
        (
            Some(1),
            "sudo-asks",
            format!(
                "installing qemu-system-arm needs root, and sudo asks for a password. Run\n    \
                 sudo apt-get update && sudo {install}\nthen run this command again"
            ),
        ),
        (
            None,
            "no-sudo",
            format!(
                "installing qemu-system-arm needs root, and there is no sudo. Run\n    \
                 (as root) apt-get update && {install}\nthen run this command again"
            ),
        ),
    ] {
        let run = setup_on(user(sudo), name);
        let stderr = run.stderr();
        assert!(!run.output.status.success());
        assert!(stderr.contains(&expected), "{stderr}");
        assert!(
            !run.log
                .iter()
                .any(|l| l.contains("apt-get update") || l.contains("apt-get install")),
            "{:?}",
            run.log
        );
    }
}

#[test]
fn nothing_missing_means_nothing_run_and_nothing_said() {
    let machine = Machine {
        targets_installed: true,
        qemu_installed: true,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "complete");
    assert!(run.output.status.success());
    assert_eq!(run.stderr(), "");
    assert_eq!(run.log, ["rustup target list --installed"]);
}
