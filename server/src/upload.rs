//! `POST /api/scenes`: upload a `.glb`. The body is the file; it is parsed in
//! memory (external buffers and images are refused, so no user-given path ever
//! touches the disk), validated, prepared and kept in the bounded scene cache.

use std::sync::Arc;

use axum::Json;
use axum::body::Bytes;
use axum::extract::{Query, Request, State};
use axum::http::StatusCode;
use continuum::PreparedScene;
use serde::Deserialize;
use serde_json::{Value, json};

use crate::error::ApiError;
use crate::state::AppState;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UploadQuery {
    /// Name to render it by: 1–40 of `a-z 0-9 - _`, starting with a letter or
    /// digit; default `upload-` and a hash of the file.
    name: Option<String>,
}

fn valid_name(n: &str) -> bool {
    (1..=40).contains(&n.len())
        && n.bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-' || b == b'_')
        && n.as_bytes()[0].is_ascii_alphanumeric()
}

pub async fn upload(
    State(state): State<Arc<AppState>>,
    query: Result<Query<UploadQuery>, axum::extract::rejection::QueryRejection>,
    request: Request,
) -> Result<(StatusCode, Json<Value>), ApiError> {
    let Query(query) = query.map_err(|e| {
        let text = e.body_text();
        let field =
            crate::render_api::unknown_or_missing_field(&text).unwrap_or_else(|| "name".into());
        ApiError::bad_request(&field, text)
    })?;
    let body = read_body(request, state.limits.max_body_bytes).await?;
    if body.is_empty() {
        return Err(ApiError::bad_request(
            "file",
            "the request body must be a .glb file",
        ));
    }
    let name = match query.name {
        Some(n) if !valid_name(&n) => {
            return Err(ApiError::bad_request(
                "name",
                format!("'{n}' is not 1-40 of a-z, 0-9, '-' and '_'"),
            ));
        }
        Some(n) => n,
        None => format!("upload-{:08x}", fnv1a(&body)),
    };
    if state.builtin_names()?.contains(&name) {
        return Err(ApiError::bad_request(
            "name",
            format!("'{name}' is a built-in scene"),
        ));
    }
    let job_state = state.clone();
    let job_name = name.clone();
    let prepared = tokio::task::spawn_blocking(move || {
        let scene = continuum::scene::load_gltf_slice(&body, &job_name)
            .map_err(|e| ApiError::bad_request("file", e.to_string()))?;
        let max = job_state.limits.max_upload_triangles;
        if scene.mesh.triangle_count() > max {
            return Err(ApiError::with_status(
                StatusCode::PAYLOAD_TOO_LARGE,
                Some("file"),
                format!(
                    "{} triangles exceed the upload limit of {max}",
                    scene.mesh.triangle_count()
                ),
            ));
        }
        let prepared = Arc::new(PreparedScene::new(scene));
        job_state.add_upload(&job_name, prepared.clone())?;
        Ok(prepared)
    })
    .await
    .map_err(|e| ApiError::internal(format!("upload failed: {e}")))??;
    Ok((
        StatusCode::CREATED,
        Json(json!({
            "scene": name,
            "triangles": prepared.triangle_count(),
            "cameras": prepared.scene.camera_names(),
            "warnings": prepared.scene.warnings,
        })),
    ))
}

/// FNV-1a of the file: a short content hash for default upload names.
fn fnv1a(bytes: &[u8]) -> u32 {
    // FNV-1a: enough to tell uploads apart in a name.
    bytes.iter().fold(0x811c_9dc5u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    })
}

/// The request body, at most `limit` bytes. A declared `Content-Length` over the
/// limit is refused before any of the body is read (a client that sent
/// `Expect: 100-continue` then never sends it).
async fn read_body(request: Request, limit: usize) -> Result<Bytes, ApiError> {
    let too_large = |what: String| {
        ApiError::with_status(
            StatusCode::PAYLOAD_TOO_LARGE,
            Some("body"),
            format!("{what} exceeds the upload limit of {limit} bytes"),
        )
    };
    let declared = request
        .headers()
        .get(axum::http::header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<usize>().ok());
    if let Some(len) = declared
        && len > limit
    {
        return Err(too_large(format!("a body of {len} bytes")));
    }
    axum::body::to_bytes(request.into_body(), limit)
        .await
        .map_err(|_| too_large("the body".into()))
}
