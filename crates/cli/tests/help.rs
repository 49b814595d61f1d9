//! Help on every command: `--help` and `-?` everywhere, and `-h` wherever it is not the image
//! height (the course's renders keep `-h HEIGHT`). Each answers on stdout with exit status 0.

use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn glint(args: &[&str]) -> Output {
    Command::new(GLINT).args(args).output().expect("glint runs")
}

/// Every subcommand, as its usage line names it.
const SUBCOMMANDS: [&[&str]; 10] = [
    &["render"],
    &["check"],
    &["merge"],
    &["diff"],
    &["denoise"],
    &["bench"],
    &["bench", "table"],
    &["bench", "rays"],
    &["bench", "make-rays"],
    &["bench", "packets"],
];

#[test]
fn every_subcommand_answers_help_with_exit_0() {
    for command in SUBCOMMANDS {
        // `render`'s -h is the image height, as in the course's form.
        let flags: &[&str] = if command == ["render"] {
            &["--help", "-?"]
        } else {
            &["--help", "-?", "-h"]
        };
        for flag in flags {
            let mut args = command.to_vec();
            args.push(flag);
            let output = glint(&args);
            let stdout = String::from_utf8_lossy(&output.stdout);
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert_eq!(output.status.code(), Some(0), "{args:?}: {stderr}");
            let usage = format!("Usage: glint {}", command.join(" "));
            assert!(
                stdout.contains(&usage),
                "{args:?}: no '{usage}' in {stdout}"
            );
            assert!(stderr.is_empty(), "{args:?}: {stderr}");
        }
    }
}

#[test]
fn the_course_form_answers_help_and_keeps_h_for_the_height() {
    for flag in ["--help", "-?"] {
        let output = glint(&[flag]);
        assert_eq!(output.status.code(), Some(0), "{flag}");
        assert!(String::from_utf8_lossy(&output.stdout).contains("Usage: glint"));
    }
    // `-h` wants a height in both rendering forms: a usage error, not help.
    for args in [&["-h"][..], &["render", "s.xml", "-h"][..]] {
        let output = glint(args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("--height"), "{args:?}: {stderr}");
    }
}
