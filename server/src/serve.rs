//! `continuum serve`.

use std::path::PathBuf;

use clap::Args;

use crate::CliError;

#[derive(Args, Debug, Default)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long)]
    pub addr: Option<String>,
    /// Folder of scenes to serve (default: the built-in scenes).
    #[arg(long)]
    pub scenes: Option<PathBuf>,
}

pub fn run(_args: &ServeArgs) -> Result<(), CliError> {
    Err(CliError::Failed(anyhow::anyhow!("serve: not built yet")))
}
