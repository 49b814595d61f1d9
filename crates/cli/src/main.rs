//! `glint`: render course ray-tracing scenes to PNG or EXR. See `glint --help`.
//!
//! This file only wires the process to the run: it parses the arguments (clap exits with
//! status 2 on usage errors and 0 for help), installs the Ctrl-C handler, and turns the
//! outcome into an exit status. What the user typed lives in `args.rs`, what a render needs in
//! `job.rs`, the run in `run.rs`.
#![forbid(unsafe_code)]

mod args;
mod bench;
mod check;
mod checkpoint;
mod denoise;
mod diff;
mod failure;
mod farm;
mod features;
mod gpu;
mod interrupt;
mod job;
mod machine;
mod memory;
mod merge;
mod passes;
mod paths;
mod preview;
mod progress;
mod report;
mod run;
mod stats;

use std::io::IsTerminal;
use std::process::ExitCode;

use clap::Parser;

use crate::args::Cli;
use crate::failure::{Failure, EXIT_INTERRUPTED};
use crate::interrupt::{Interrupt, SignalAction};

/// Shared with the Ctrl-C handler, which must be `'static`.
static INTERRUPT: Interrupt = Interrupt::new();

fn main() -> ExitCode {
    let mut cli = Cli::parse();
    if matches!(cli.command, Some(crate::args::Command::Bench(_))) {
        let Some(crate::args::Command::Bench(args)) = cli.command.take() else {
            unreachable!("matched just above");
        };
        return match bench::run(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(message) => {
                eprintln!("error: {message}");
                ExitCode::FAILURE
            }
        };
    }
    if let Some(crate::args::Command::Diff(args)) = &cli.command {
        let status = diff::run(args, &mut std::io::stdout(), &mut std::io::stderr());
        return ExitCode::from(status);
    }
    if let Some(crate::args::Command::Check { scenes, limits, .. }) = &cli.command {
        let (resolved, _) = limits.resolve();
        let status = check::run(
            scenes,
            &resolved,
            &limits.defines,
            &limits.model_options(),
            limits.strict,
            &mut std::io::stderr(),
        );
        return ExitCode::from(status);
    }
    if matches!(cli.command, Some(crate::args::Command::Merge(_))) {
        let Some(crate::args::Command::Merge(args)) = cli.command.take() else {
            unreachable!("matched just above");
        };
        handle_signals();
        return match merge::run(&args, &INTERRUPT, &mut std::io::stderr()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(failure) => fail(&failure),
        };
    }
    if let Some(crate::args::Command::Denoise(args)) = &cli.command {
        return match denoise::run(args, &mut std::io::stderr()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(failure) => fail(&failure),
        };
    }
    let available = std::thread::available_parallelism().map_or(1, |n| n.get());
    let job = match cli.into_job(available) {
        Ok(job) => job,
        Err(error) => return fail(&Failure::Usage(error)),
    };
    if let Err(failure) = run::refuse_missing(&job) {
        return fail(&failure);
    }
    if job.device == crate::args::DeviceArg::Gpu {
        // Before any thread starts: it sets an environment variable.
        gpu::quiet_display_probe();
    }

    handle_signals();

    // Not locked: the progress bar draws from the render threads.
    let progress_bar = std::io::stderr().is_terminal();
    let run = |tiles: Option<&preview::TileSink>| {
        run::run(
            &job,
            &INTERRUPT,
            &mut std::io::stderr(),
            progress_bar,
            tiles,
        )
    };
    let window = job.preview.and_then(|(width, height)| {
        let settings = &job.settings;
        preview::Preview::open(
            width as usize,
            height as usize,
            settings.width,
            settings.height,
        )
        .map_err(|why| eprintln!("warning: no preview window ({why}); rendering without it"))
        .ok()
    });
    let outcome = match window {
        Some(window) => window.run_while(job.preview_close, &|| INTERRUPT.requested(), |tiles| {
            run(Some(&tiles))
        }),
        None => run(None),
    };
    match outcome {
        Ok(_) => ExitCode::SUCCESS,
        Err(failure) => fail(&failure),
    }
}

/// Ctrl-C and SIGTERM through `INTERRUPT`, for a render and for `glint merge`. Without a
/// handler Ctrl-C would still kill the process, but a merge or render killed while writing
/// would leave its temporary file; a failure to install it is only a note. With ctrlc's
/// `termination` feature SIGTERM (and SIGHUP) take the same path as Ctrl-C.
fn handle_signals() {
    if let Err(error) = ctrlc::set_handler(|| match INTERRUPT.on_signal() {
        SignalAction::ExitNow => {
            eprintln!("\nerror: {}", Failure::Interrupted);
            std::process::exit(EXIT_INTERRUPTED.into());
        }
        SignalAction::Cancel | SignalAction::Ignore => {}
    }) {
        eprintln!("note: cannot handle Ctrl-C: {error}");
    }
}

fn fail(failure: &Failure) -> ExitCode {
    eprintln!("error: {failure}");
    ExitCode::from(failure.exit_code())
}
