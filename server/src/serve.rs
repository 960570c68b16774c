//! `continuum serve`: the HTTP service on a scenes folder, shut down gracefully
//! on SIGTERM or Ctrl-C.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use continuum_server::{AppState, Limits, app};

use crate::{CliError, scenes_dir};

#[derive(Args, Debug, Default)]
pub struct ServeArgs {
    /// Address to listen on [default: 127.0.0.1:8080].
    #[arg(long)]
    pub addr: Option<String>,
    /// Folder of scenes to serve (default: the built-in scenes).
    #[arg(long)]
    pub scenes: Option<PathBuf>,
    /// Most pixels in one render [default: 4096000].
    #[arg(long)]
    pub max_pixels: Option<u64>,
    /// Renders running at once [default: cores].
    #[arg(long)]
    pub max_concurrent: Option<usize>,
    /// Most samples per pixel an anti-aliasing mode may take [default: 256].
    #[arg(long)]
    pub max_samples_per_pixel: Option<u32>,
    /// Most samples in one render, pixels × samples per pixel [default: 65536000].
    #[arg(long)]
    pub max_samples: Option<u64>,
    /// Renders that may wait for a slot; more are answered 503 [default: 4 × cores].
    #[arg(long)]
    pub max_queued: Option<usize>,
    /// Seconds before a render is answered 504 [default: 60].
    #[arg(long)]
    pub render_timeout: Option<f64>,
    /// Largest request body or upload in MiB [default: 32].
    #[arg(long)]
    pub max_body_mib: Option<usize>,
    /// Most triangles of an uploaded scene [default: 2000000].
    #[arg(long)]
    pub max_upload_triangles: Option<usize>,
    /// Memory for prepared scenes in MiB [default: 2048].
    #[arg(long)]
    pub cache_mib: Option<usize>,
    /// Log lines as plain text (colours only on a terminal) or as one JSON object each.
    #[arg(long, value_enum, default_value_t = LogFormat::Text)]
    pub log_format: LogFormat,
}

/// How `continuum serve` writes its log (standard error).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    #[default]
    Text,
    Json,
}

impl ServeArgs {
    /// The limits these flags ask for, each checked.
    fn limits(&self) -> Result<Limits, CliError> {
        let mut l = Limits::default();
        let positive = |name: &str, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(CliError::Usage(format!("--{name}: must be positive")))
            }
        };
        if let Some(v) = self.max_pixels {
            positive("max-pixels", v > 0)?;
            l.max_pixels = v;
        }
        if let Some(v) = self.max_concurrent {
            positive("max-concurrent", v > 0)?;
            l.max_concurrent_renders = v;
        }
        if let Some(v) = self.max_samples_per_pixel {
            positive("max-samples-per-pixel", v > 0)?;
            l.max_samples_per_pixel = v;
        }
        if let Some(v) = self.max_samples {
            positive("max-samples", v > 0)?;
            l.max_samples = v;
        }
        if let Some(v) = self.max_queued {
            l.max_queued_renders = v;
        }
        if let Some(v) = self.render_timeout {
            positive("render-timeout", v > 0.0 && v.is_finite())?;
            l.render_timeout = std::time::Duration::from_secs_f64(v);
        }
        if let Some(v) = self.max_body_mib {
            positive("max-body-mib", v > 0)?;
            l.max_body_bytes = v << 20;
        }
        if let Some(v) = self.max_upload_triangles {
            positive("max-upload-triangles", v > 0)?;
            l.max_upload_triangles = v;
        }
        if let Some(v) = self.cache_mib {
            positive("cache-mib", v > 0)?;
            l.max_cache_bytes = v << 20;
        }
        Ok(l)
    }
}

pub fn run(args: &ServeArgs) -> Result<(), CliError> {
    use std::io::IsTerminal;
    let filter =
        tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into());
    let log = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    match args.log_format {
        LogFormat::Json => log.json().init(),
        // Colour codes only where a terminal shows them, not in files or `docker logs`.
        LogFormat::Text => log.with_ansi(std::io::stderr().is_terminal()).init(),
    }
    let addr = args.addr.clone().unwrap_or_else(|| "127.0.0.1:8080".into());
    let dir = scenes_dir(args.scenes.as_ref());
    if !dir.is_dir() {
        return Err(CliError::Usage(format!(
            "--scenes: {} is not a folder",
            dir.display()
        )));
    }
    let limits = args.limits()?;
    let runtime = tokio::runtime::Runtime::new().context("starting the async runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(&addr)
            .await
            .map_err(|e| CliError::Usage(format!("--addr: cannot listen on {addr}: {e}")))?;
        let url = match listener.local_addr() {
            Ok(a) if a.ip().is_unspecified() => format!("http://localhost:{}/", a.port()),
            Ok(a) => format!("http://{a}/"),
            Err(_) => format!("http://{addr}/"),
        };
        tracing::info!(%addr, %url, scenes = %dir.display(), ?limits, "continuum serving");
        // The one line a user needs, on standard output whatever the log says.
        println!("continuum: open {url} (Ctrl-C stops)");
        let state = AppState::new(dir.clone(), limits);
        axum::serve(listener, app(state))
            .with_graceful_shutdown(shutdown_signal())
            .await
            .context("serving")?;
        tracing::info!("shut down");
        Ok(())
    })
}

async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        if let Ok(mut s) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        {
            s.recv().await;
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {},
        () = term => {},
    }
}
