//! The continuum render service: an axum [`app`] over a scenes folder.
//!
//! Routes: `GET /` (the web page), `GET /healthz`, `GET /metrics` (Prometheus), `GET /api/scenes`, `GET /api/algorithms`,
//! `POST /api/render` (a RenderRequest in the CLI's words → the `render --json`
//! document plus the requested images as base64 PNG), `GET /api/render.png`
//! (the same fields as query parameters → one PNG), `POST /api/scenes` (upload a
//! `.glb`, kept in the bounded in-memory cache). Errors are
//! `{ "error": "...", "field": "..." }` with a 4xx status.

mod error;
mod metrics;
mod observe;
mod render_api;
mod state;
mod upload;

use std::sync::Arc;

use axum::Router;
use axum::routing::{get, post};

pub use error::ApiError;
pub use render_api::RenderBody;
pub use state::{AppState, Limits};

/// The web page, embedded in the binary (no build step).
const INDEX_HTML: &str = include_str!("../web/index.html");

async fn index() -> axum::response::Html<&'static str> {
    axum::response::Html(INDEX_HTML)
}

/// The service's router over `state`.
pub fn app(state: Arc<AppState>) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/healthz", get(|| async { "ok\n" }))
        .route("/api/scenes", get(render_api::scenes).post(upload::upload))
        .route("/api/algorithms", get(render_api::algorithms))
        .route("/api/render", post(render_api::render_json))
        .route("/api/render.png", get(render_api::render_png))
        .route("/metrics", get(observe::metrics))
        .fallback(|| async { ApiError::not_found("path", "no such route") })
        .method_not_allowed_fallback(|| async { ApiError::method_not_allowed() })
        .layer(axum::extract::DefaultBodyLimit::max(
            state.limits.max_body_bytes,
        ))
        .layer(axum::middleware::from_fn_with_state(
            state.clone(),
            observe::track,
        ))
        .with_state(state)
}
