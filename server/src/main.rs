//! `continuum`: the render service, one-off renders, and (later) comparison runs.
//! With no subcommand it serves the built-in scenes.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cli_render;
mod compare;
mod hardcases;
mod help;
mod plot;
mod serve;

#[derive(Parser, Debug)]
#[command(
    name = "continuum",
    version,
    about = "The road between rasterization and ray casting, rendered and measured"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// GPU adapter for the GPU algorithms: a case-insensitive part of its name
    /// (e.g. `llvmpipe`); CONTINUUM_ADAPTER otherwise; the first high-performance
    /// adapter without either. CONTINUUM_GPU_ATOMICS=two-pass forces the compute
    /// kernels' 32-bit visibility.
    #[arg(long, global = true)]
    adapter: Option<String>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Serve the HTTP API on the built-in scenes (the default command).
    Serve(serve::ServeArgs),
    /// Render one image and print or write what it cost.
    Render(cli_render::RenderArgs),
    /// Run every algorithm and peer on scenes and write what each cost.
    Compare(compare::CompareArgs),
    /// Run the numerical hard-case suite; exit status 1 on any violation.
    Hardcases(hardcases::HardcasesArgs),
}

/// mimalloc keeps freed pages for the next allocation: every render allocates
/// frame-sized buffers (setups, tiles, the framebuffer), which the system
/// allocator maps fresh (and the kernel zeroes) each time.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// `mi_option_purge_delay` of mimalloc's `mi_option_t` (`mimalloc.h`).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Tells mimalloc never to return freed pages to the system. By default it
/// returns the pages of a freed large block at once, and the next render's
/// setups (100+ MB on a million triangles) fault in fresh pages that the
/// kernel zeroes: about 150 faults of 2 MB per `teapots` frame (`perf stat
/// -e page-faults`), none with this; its frames take 0.95–0.96× (three
/// A/B runs of 4–6 alternated rounds, 1080p), the bunny's are unchanged.
/// The process keeps the memory of its largest render for the next.
fn keep_freed_memory() {
    // SAFETY: `mi_option_set` stores an integer option (no pointers, any
    // value is valid); called at the start of `main`, before any thread.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) };
}

fn main() -> ExitCode {
    if let Some(dir) = continuum::mesa::private_runtime_dir() {
        // SAFETY: the first statement of `main`, before any thread exists, so
        // nothing reads the environment while it changes.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) };
    }
    keep_freed_memory();
    let cli = Cli::parse();
    if let Some(name) = &cli.adapter {
        continuum::choose_gpu_adapter(name);
    }
    let result = match cli.command {
        Some(Command::Render(args)) => cli_render::run(&args),
        Some(Command::Compare(args)) => compare::run(&args),
        Some(Command::Serve(args)) => serve::run(&args),
        Some(Command::Hardcases(args)) => match hardcases::run(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::FAILURE,
            Err(e) => Err(e),
        },
        None => serve::run(&serve::ServeArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Usage(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
        Err(CliError::Failed(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// How a command failed: a bad argument (exit 2) or a failure while running (exit 1).
#[derive(Debug)]
pub enum CliError {
    Usage(String),
    Failed(anyhow::Error),
}

impl From<anyhow::Error> for CliError {
    fn from(e: anyhow::Error) -> Self {
        CliError::Failed(e)
    }
}

/// Writes `text` to standard output. A reader that went away (`| head`) is
/// not a failure: the rest is simply not written.
pub fn write_stdout(text: &str) -> Result<(), CliError> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CliError::Failed(
            anyhow::Error::new(e).context("writing to standard output"),
        )),
        _ => Ok(()),
    }
}

/// The scenes folder: `--scenes`, else the built-in default.
pub fn scenes_dir(arg: Option<&PathBuf>) -> PathBuf {
    arg.cloned()
        .unwrap_or_else(continuum::scene::default_scenes_dir)
}
