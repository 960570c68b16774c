//! The continuum render service: an axum [`app`] over a scenes folder.
//!
//! Routes: `GET /healthz`, `GET /api/scenes`, `GET /api/algorithms`,
//! `POST /api/render` (a RenderRequest in the CLI's words → the `render --json`
//! document plus the requested images as base64 PNG), `GET /api/render.png`
//! (the same fields as query parameters → one PNG). Errors are
//! `{ "error": "...", "field": "..." }` with a 4xx status.

mod error;
mod render_api;
mod state;

use std::sync::Arc;

use axum::Router;
use axum::routing::{get, post};

pub use error::ApiError;
pub use render_api::RenderBody;
pub use state::{AppState, Limits};

/// The service's router over `state`.
pub fn app(state: Arc<AppState>) -> Router {
    Router::new()
        .route("/healthz", get(|| async { "ok\n" }))
        .route("/api/scenes", get(render_api::scenes))
        .route("/api/algorithms", get(render_api::algorithms))
        .route("/api/render", post(render_api::render_json))
        .route("/api/render.png", get(render_api::render_png))
        .fallback(|| async { ApiError::not_found("path", "no such route") })
        .with_state(state)
}
