//! The service watched: the middleware that counts and logs every request,
//! and `GET /metrics`, both over the state's [`crate::metrics::Metrics`].

use std::sync::Arc;

use axum::extract::{MatchedPath, Request, State};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::state::AppState;

/// Middleware: counts every request by its matched route and final status, and
/// logs it (structured, through `tracing`).
pub async fn track(State(state): State<Arc<AppState>>, request: Request, next: Next) -> Response {
    let route = request
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_string(), |p| p.as_str().to_string());
    let method = request.method().clone();
    let start = std::time::Instant::now();
    let response = next.run(request).await;
    let status = response.status().as_u16();
    state.metrics.count_request(&route, status);
    tracing::info!(%method, route, status, ms = start.elapsed().as_secs_f64() * 1e3, "request");
    response
}

/// `GET /metrics`.
pub async fn metrics(State(state): State<Arc<AppState>>) -> impl IntoResponse {
    let in_flight = state.limits.max_concurrent_renders.max(1) - state.renders.available_permits();
    let (cached, bytes) = state.cache_usage();
    (
        [(
            axum::http::header::CONTENT_TYPE,
            "text/plain; version=0.0.4",
        )],
        state.metrics.render_text(
            in_flight,
            state.queued.load(std::sync::atomic::Ordering::SeqCst),
            cached,
            bytes,
        ),
    )
}
