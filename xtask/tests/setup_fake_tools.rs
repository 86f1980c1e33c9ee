//! `cargo xtask setup` (the install step `run`, `test` and `bench` begin
//! with) against fake rustup, apt-get, apt-cache, dpkg-query, dpkg, dpkg-deb,
//! sudo and id: shell scripts in a directory that is the whole PATH. They
//! print on stdout as the real ones do (apt-get update's 165 lines), log how
//! they were called, and the fake apt-get "installs" QEMU by writing a
//! qemu-system-arm script, the fake dpkg-deb "unpacks" one into the
//! directory `XTASK_QEMU_DIR` names. Nothing is really installed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const RUSTUP: &str = r#"#!/bin/sh
echo "rustup $*" >> "$FAKE_LOG"
case "$1 $2" in
  "target list") echo x86_64-unknown-linux-gnu; for t in $FAKE_TARGETS; do echo "$t"; done ;;
  "target add") echo "info: downloading component 'rust-std' for '$3'" ;;
esac
"#;

/// `install -s qemu-system-arm` prints `$FAKE_PLAN`; `install -s` of the
/// libraries prints `$FAKE_LIBRARY_PLAN`.
const APT_GET: &str = r#"#!/bin/sh
echo "apt-get $*" >> "$FAKE_LOG"
case "$1 $2" in
  "--version "*) echo "apt 2.6.1 (amd64)" ;;
  "update "*) i=0; while [ $i -lt 165 ]; do echo "Get:$i http://mirror.invalid bookworm InRelease"; i=$((i+1)); done ;;
  "install -s")
    case "$*" in
      *qemu-system-arm) /bin/cat "$FAKE_PLAN" ;;
      *) /bin/cat "$FAKE_LIBRARY_PLAN" ;;
    esac ;;
  "install -y")
    case "$*" in
      *qemu-system-arm)
        echo "Setting up qemu-system-arm (1:7.2+dfsg-7) ..."
        printf '#!/bin/sh\necho "QEMU emulator version 7.2.0"\n' > "$FAKE_DIR/qemu-system-arm"
        /bin/chmod +x "$FAKE_DIR/qemu-system-arm" ;;
      *) echo "Setting up libfdt1 (1.6.1-4+b1) ..." ;;
    esac ;;
  "download "*)
    echo "Get:1 http://mirror.invalid bookworm/main amd64 qemu-system-arm amd64 1:7.2+dfsg-7 [8909 kB]"
    echo fake > "qemu-system-arm_1%3a7.2+dfsg-7_amd64.deb" ;;
esac
"#;

const APT_CACHE: &str = r#"#!/bin/sh
echo "apt-cache $*" >> "$FAKE_LOG"
case "$1" in
  policy) printf 'qemu-system-arm:\n  Installed: (none)\n  Candidate: 1:7.2+dfsg-7\n' ;;
  show) printf 'Package: qemu-system-arm\nVersion: 1:7.2+dfsg-7\nDepends: %s\n' "$FAKE_DEPENDS" ;;
esac
"#;

/// Lists `$FAKE_INSTALLED` as installed, whatever it is asked.
const DPKG_QUERY: &str = r#"#!/bin/sh
echo "dpkg-query $1 $2" >> "$FAKE_LOG"
for p in $FAKE_INSTALLED; do printf '%s\tinstalled\t1.0\n' "$p"; done
"#;

/// Every installed version meets its bound.
const DPKG: &str = "#!/bin/sh\nexit 0\n";

/// `dpkg-deb -x DEB DIR` unpacks a qemu-system-arm that says it is 7.2.
const DPKG_DEB: &str = r#"#!/bin/sh
echo "dpkg-deb $1 $(/usr/bin/basename "$2") $(/usr/bin/basename "$3")" >> "$FAKE_LOG"
/bin/mkdir -p "$3/usr/bin"
printf '#!/bin/sh\necho "QEMU emulator version 7.2.0 (Debian 1:7.2+dfsg-7)"\n' > "$3/usr/bin/qemu-system-arm"
/bin/chmod +x "$3/usr/bin/qemu-system-arm"
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

/// Installing the libraries the unpacked QEMU needs: nothing goes.
const LIBRARY_PLAN: &str = "\
The following NEW packages will be installed:
  libfdt1
Inst libfdt1 (1.6.1-4+b1 Debian:12 [amd64])
";

/// Installing the libraries would remove something too.
const REMOVING_LIBRARY_PLAN: &str = "\
The following packages will be REMOVED:
  libfdt2
Remv libfdt2 [1.7.0]
Inst libfdt1 (1.6.1-4+b1 Debian:12 [amd64])
";

/// qemu-system-arm's Depends, shortened: libfdt1 is the one not installed.
const DEPENDS: &str = "libc6 (>= 2.34), libfdt1 (>= 1.6.1), \
    qemu-system-common (= 1:7.2+dfsg-7), qemu-system-data (>> 1:7.2+dfsg~)";

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
    library_plan: &'static str,
    /// What dpkg-query says is installed.
    installed: &'static str,
    targets_installed: bool,
    qemu_installed: bool,
}

impl Machine {
    const ROOT_WITHOUT_ANYTHING: Machine = Machine {
        uid: 0,
        sudo: None,
        plan: CLEAN_PLAN,
        library_plan: LIBRARY_PLAN,
        installed: "libc6",
        targets_installed: false,
        qemu_installed: false,
    };
}

/// What `xtask setup` did: its output, and the fakes' log of calls.
struct Run {
    output: Output,
    log: Vec<String>,
    qemu_installed: bool,
    /// Whether the fallback left a qemu-system-arm in `XTASK_QEMU_DIR`.
    qemu_unpacked: bool,
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
    write_script(&bin, "apt-cache", APT_CACHE);
    write_script(&bin, "dpkg-query", DPKG_QUERY);
    write_script(&bin, "dpkg", DPKG);
    write_script(&bin, "dpkg-deb", DPKG_DEB);
    write_script(&bin, "id", ID);
    if machine.sudo.is_some() {
        write_script(&bin, "sudo", SUDO);
    }
    if machine.qemu_installed {
        write_script(
            &bin,
            "qemu-system-arm",
            "#!/bin/sh\necho QEMU emulator version 7.2.0\n",
        );
    }
    let plan = dir.join("plan.txt");
    std::fs::write(&plan, machine.plan).unwrap();
    let library_plan = dir.join("library-plan.txt");
    std::fs::write(&library_plan, machine.library_plan).unwrap();
    let qemu_dir = dir.join("qemu-deb");
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
        .env("FAKE_LIBRARY_PLAN", &library_plan)
        .env("FAKE_DEPENDS", DEPENDS)
        .env("FAKE_INSTALLED", machine.installed)
        .env("XTASK_QEMU_DIR", &qemu_dir)
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
        qemu_unpacked: qemu_dir.join("root/usr/bin/qemu-system-arm").exists(),
    };
    std::fs::remove_dir_all(&dir).unwrap();
    run
}

/// Each of `texts` is in `stderr`, each after the one before.
fn assert_in_order(stderr: &str, texts: &[&str]) {
    let mut from = 0;
    for text in texts {
        match stderr[from..].find(text) {
            Some(at) => from += at + text.len(),
            None => panic!("{text:?} after byte {from} of\n{stderr}"),
        }
    }
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
    assert_in_order(
        &stderr,
        &[
            "thumbv7em-none-eabihf (the Cortex-M4F boards' firmware)",
            "info: downloading component",
            "install the Debian package qemu-system-arm",
            "Get:0 ",
            "Get:164 ",
            "apt-get installs 3 package(s): qemu-system-data",
            "Setting up qemu-system-arm",
        ],
    );
}

/// The machine of the issue: installing qemu-system-arm would remove
/// qemu-utils, so xtask installs only the missing library, downloads and
/// unpacks the package, and says each step before it starts.
#[test]
fn a_plan_that_would_remove_a_package_unpacks_qemu_instead() {
    let machine = Machine {
        plan: REMOVING_PLAN,
        targets_installed: true,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "removal");
    let stderr = run.stderr();
    assert!(run.output.status.success(), "{stderr}");
    assert!(!run.qemu_installed);
    assert!(run.qemu_unpacked);
    assert_eq!(String::from_utf8_lossy(&run.output.stdout), "");
    assert_eq!(
        run.log,
        [
            "rustup target list --installed",
            "apt-get --version",
            "apt-get update",
            "apt-get install -s --no-install-recommends qemu-system-arm",
            "apt-cache policy qemu-system-arm",
            "apt-cache show qemu-system-arm=1:7.2+dfsg-7",
            "dpkg-query -W -f",
            "apt-get install -s --no-install-recommends libfdt1",
            "apt-get install -y --no-install-recommends --no-remove libfdt1",
            "apt-get download qemu-system-arm=1:7.2+dfsg-7",
            "dpkg-deb -x qemu-system-arm_1%3a7.2+dfsg-7_amd64.deb root",
        ]
    );
    assert_in_order(
        &stderr,
        &[
            "installing qemu-system-arm would remove qemu-utils, and xtask never",
            "step 1/3: installing with apt-get the shared libraries qemu-system-arm \
             1:7.2+dfsg-7 needs that are missing: libfdt1 (its Depends less \
             qemu-system-common and qemu-system-data",
            "Setting up libfdt1",
            "step 2/3: downloading the package",
            "Get:1 http://mirror.invalid bookworm/main",
            "step 3/3: unpacking it",
            "runs: QEMU emulator version 7.2.0",
        ],
    );
}

/// The libraries already there and QEMU unpacked: nothing is installed, and
/// the next run finds the unpacked QEMU without asking apt anything.
#[test]
fn with_the_libraries_installed_the_fallback_needs_no_root() {
    let machine = Machine {
        uid: 1000,
        sudo: None,
        plan: REMOVING_PLAN,
        installed: "libc6 libfdt1",
        targets_installed: true,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "no-root-fallback");
    let stderr = run.stderr();
    assert!(run.output.status.success(), "{stderr}");
    assert!(run.qemu_unpacked);
    assert!(stderr.contains("step 1/3: the shared libraries qemu-system-arm 1:7.2+dfsg-7 needs are installed already"), "{stderr}");
    assert!(
        !run.log
            .iter()
            .any(|l| l.contains("apt-get update") || l.contains("install -y")),
        "{:?}",
        run.log
    );
}

#[test]
fn a_plan_that_would_downgrade_a_package_unpacks_qemu_instead() {
    let machine = Machine {
        plan: DOWNGRADING_PLAN,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "downgrade");
    let stderr = run.stderr();
    assert!(run.output.status.success(), "{stderr}");
    assert!(
        stderr.contains("installing qemu-system-arm would downgrade libfdt1,"),
        "{stderr}"
    );
    assert!(run.qemu_unpacked && !run.qemu_installed);
}

/// When even the libraries' plan would remove something, xtask stops there
/// with the packages named and the command to run if you accept it.
#[test]
fn a_library_plan_that_would_remove_a_package_is_refused_with_the_command_to_run() {
    let machine = Machine {
        plan: REMOVING_PLAN,
        library_plan: REMOVING_LIBRARY_PLAN,
        ..Machine::ROOT_WITHOUT_ANYTHING
    };
    let run = setup_on(machine, "library-removal");
    let stderr = run.stderr();
    assert!(!run.output.status.success());
    assert!(!run.qemu_installed && !run.qemu_unpacked);
    assert!(
        stderr.contains(
            "xtask: installing libfdt1 would remove libfdt2, and xtask never \
             removes or downgrades an installed package."
        ),
        "{stderr}"
    );
    assert!(stderr.contains("\n    apt-get install --no-install-recommends libfdt1\n"));
    assert!(
        !run.log
            .iter()
            .any(|l| l.contains("install -y") || l.contains("download")),
        "{:?}",
        run.log
    );
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
        // The simulation needs no root; nothing else apt-get does runs.
        assert!(
            !run.log
                .iter()
                .any(|l| l.contains("apt-get update") || l.contains("apt-get install -y")),
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
