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
}

pub fn run(args: &ServeArgs) -> Result<(), CliError> {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .init();
    let addr = args.addr.clone().unwrap_or_else(|| "127.0.0.1:8080".into());
    let dir = scenes_dir(args.scenes.as_ref());
    if !dir.is_dir() {
        return Err(CliError::Usage(format!(
            "--scenes: {} is not a folder",
            dir.display()
        )));
    }
    let runtime = tokio::runtime::Runtime::new().context("starting the async runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(&addr)
            .await
            .map_err(|e| CliError::Usage(format!("--addr: cannot listen on {addr}: {e}")))?;
        let state = AppState::new(dir.clone(), Limits::default());
        tracing::info!(%addr, scenes = %dir.display(), "continuum serving");
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
