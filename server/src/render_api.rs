//! The render endpoints and the listings.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use axum::Json;
use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use base64::Engine;
use continuum::{
    AaMode, AlgorithmId, Bounds, Camera, CameraSpec, FieldError, Overlays, Precision,
    PreparedScene, RenderOutput, RenderRequest, RenderWords, Settings, Viewport, draw_overlays,
    maps,
};
use serde::Deserialize;
use serde_json::{Value, json};

use crate::error::ApiError;
use crate::state::AppState;

/// A RenderRequest, in the CLI's words.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderBody {
    pub scene: String,
    pub algorithm: String,
    pub camera: Option<CameraSpec>,
    pub oracles: Option<String>,
    pub viewport: Option<String>,
    pub aa: Option<String>,
    pub precision: Option<String>,
    pub texture_filter: Option<String>,
    pub size: Option<String>,
    pub outputs: Option<Vec<String>>,
    /// Overlays drawn over every image: `"frusta,tiles"` or `["frusta", "tiles"]`.
    pub overlays: Option<OverlayWords>,
}

/// The overlays in words: one comma-separated string, or a list.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum OverlayWords {
    Text(String),
    List(Vec<String>),
    /// Anything else: an error naming `overlays`.
    Other(Value),
}

impl OverlayWords {
    fn text(&self) -> Result<String, ApiError> {
        match self {
            OverlayWords::Text(t) => Ok(t.clone()),
            OverlayWords::List(l) => Ok(l.join(",")),
            OverlayWords::Other(v) => Err(ApiError::bad_request(
                "overlays",
                format!("{v} is neither a string nor a list of strings"),
            )),
        }
    }
}

/// Image outputs a request may ask for.
const OUTPUTS: [&str; 4] = ["color", "edge_evals", "depth", "triangle_id"];

impl RenderBody {
    /// The body's words, for the front door every front end shares.
    fn words(&self) -> Result<RenderWords, ApiError> {
        Ok(RenderWords {
            scene: self.scene.clone(),
            algorithm: self.algorithm.clone(),
            camera: self.camera.clone(),
            oracles: self.oracles.clone(),
            viewport: self.viewport.clone(),
            aa: self.aa.clone(),
            precision: self.precision.clone(),
            texture_filter: self.texture_filter.clone(),
            size: self.size.clone(),
            overlays: self.overlays.as_ref().map(OverlayWords::text).transpose()?,
        })
    }
}

/// A body checked against the limits and the renderer's capabilities, ready
/// to render once its scene is at hand.
struct Checked {
    scene: String,
    settings: Settings,
}

fn check(body: &RenderBody, state: &AppState) -> Result<Checked, ApiError> {
    let names = state.scene_names()?;
    if !names.contains(&body.scene) {
        return Err(ApiError::bad_request(
            "scene",
            format!(
                "unknown scene '{}'; scenes are: {}",
                body.scene,
                names.join(", ")
            ),
        ));
    }
    let settings = body.words()?.settings()?;
    let (width, height, aa) = (settings.width, settings.height, settings.aa);
    if u64::from(width) * u64::from(height) > state.limits.max_pixels {
        return Err(FieldError::new(
            "size",
            format!(
                "{width}x{height} exceeds the limit of {} pixels",
                state.limits.max_pixels
            ),
        )
        .into());
    }
    let samples_per_pixel = aa.coverage_samples();
    if samples_per_pixel > state.limits.max_samples_per_pixel {
        return Err(FieldError::new(
            "aa",
            format!(
                "{samples_per_pixel} samples per pixel exceed the limit of {}",
                state.limits.max_samples_per_pixel
            ),
        )
        .into());
    }
    let samples = u64::from(width) * u64::from(height) * u64::from(samples_per_pixel);
    if samples > state.limits.max_samples {
        return Err(FieldError::new(
            "aa",
            format!(
                "{width}x{height} with {aa} is {samples} samples, over the limit of {}; use a smaller size or mode",
                state.limits.max_samples
            ),
        )
        .into());
    }
    if let Some(bad) = body
        .outputs
        .iter()
        .flatten()
        .find(|o| !OUTPUTS.contains(&o.as_str()))
    {
        return Err(ApiError::bad_request(
            "outputs",
            format!(
                "unknown output '{bad}'; outputs are: {}",
                OUTPUTS.join(", ")
            ),
        ));
    }
    // What the renderer would refuse, refused before the render is queued.
    continuum::check(&settings.probe()?, None)?;
    Ok(Checked {
        scene: body.scene.clone(),
        settings,
    })
}

/// Renders on the blocking pool, at most `max_concurrent_renders` at once; up to
/// `max_queued_renders` more wait for a slot, and beyond that the answer is 503.
async fn run(state: Arc<AppState>, c: Checked) -> Result<Rendered, ApiError> {
    let timeout = state.limits.render_timeout;
    let permit = match state.renders.clone().try_acquire_owned() {
        Ok(p) => p,
        Err(_) => {
            let _ticket = state.queue_ticket().ok_or_else(ApiError::overloaded)?;
            let wait = tokio::time::timeout(timeout, state.renders.clone().acquire_owned());
            wait.await
                .map_err(|_| ApiError::overloaded())?
                .map_err(|_| ApiError::internal("render slots closed"))?
        }
    };
    let job_state = state.clone();
    // Set when the answer is 504: the render stops at its next tile and gives
    // its slot back instead of finishing for nobody.
    let cancel = Arc::new(AtomicBool::new(false));
    let job_cancel = cancel.clone();
    let job = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let prepared = job_state.prepared(&c.scene)?;
        let request = c.settings.request(&prepared.scene)?;
        let out = continuum::render_cancellable(&prepared, &request, &job_cancel)
            .map_err(|e| ApiError::bad_request(e.field, e.to_string()))?;
        job_state
            .metrics
            .observe_render(request.algorithm.as_str(), out.stats.time_ms.total / 1e3);
        Ok(Rendered {
            scene: prepared.scene.name.clone(),
            camera: request.camera.name,
            overlays: c.settings.overlays,
            out,
            prepared,
        })
    });
    // The job keeps its render slot until it ends; a timed-out render is
    // cancelled, so it ends within a tile's time.
    let result = tokio::time::timeout(timeout, job).await.map_err(|_| {
        cancel.store(true, Ordering::Relaxed);
        ApiError::with_status(
            axum::http::StatusCode::GATEWAY_TIMEOUT,
            Some("timeout"),
            format!(
                "the render did not finish within {} s and was cancelled",
                timeout.as_secs_f64()
            ),
        )
    })?;
    result.map_err(|e| ApiError::internal(format!("render failed: {e}")))?
}

/// A finished render, with what its images need.
struct Rendered {
    out: RenderOutput,
    prepared: Arc<PreparedScene>,
    scene: String,
    camera: String,
    overlays: Overlays,
}

impl Rendered {
    /// The PNG of output `name`, with the overlays asked for drawn over it.
    fn image(&self, name: &str) -> Vec<u8> {
        let fb = &self.out.framebuffer;
        let mut img = match name {
            "edge_evals" => maps::edge_eval_image(fb),
            "depth" => maps::depth_image(fb),
            "triangle_id" => maps::triangle_id_image(fb),
            _ => maps::color_image(fb),
        };
        draw_overlays(&mut img, self.overlays, &self.out, &self.prepared);
        maps::png_bytes(&img)
    }
}

/// `POST /api/render`.
pub async fn render_json(
    State(state): State<Arc<AppState>>,
    headers: axum::http::HeaderMap,
    body: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> Result<Json<Value>, ApiError> {
    ApiError::require_json(&headers)?;
    let body = body.map_err(|e| ApiError::body(&e))?;
    let body: RenderBody = serde_json::from_slice(&body).map_err(|e| json_error(&e))?;
    let checked = check(&body, &state)?;
    let rendered = run(state, checked).await?;
    let out = &rendered.out;
    let mut doc = serde_json::to_value(out.summary(&rendered.scene, &rendered.camera))
        .map_err(|e| ApiError::internal(e.to_string()))?;
    let outputs = body.outputs.unwrap_or_else(|| vec!["color".into()]);
    let images: serde_json::Map<String, Value> = outputs
        .iter()
        .map(|o| {
            let png = base64::engine::general_purpose::STANDARD.encode(rendered.image(o));
            (o.clone(), Value::String(png))
        })
        .collect();
    doc["images"] = Value::Object(images);
    // The next render of this size reuses the frame's memory.
    rendered.out.framebuffer.recycle();
    Ok(Json(doc))
}

/// Query form of [`RenderBody`] for `GET /api/render.png`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderQuery {
    scene: String,
    algorithm: String,
    camera: Option<String>,
    oracles: Option<String>,
    viewport: Option<String>,
    aa: Option<String>,
    precision: Option<String>,
    texture_filter: Option<String>,
    size: Option<String>,
    output: Option<String>,
    overlays: Option<String>,
}

/// `GET /api/render.png`.
pub async fn render_png(
    State(state): State<Arc<AppState>>,
    query: Result<Query<RenderQuery>, axum::extract::rejection::QueryRejection>,
) -> Result<Response, ApiError> {
    let Query(q) = query.map_err(|e| {
        let text = e.body_text();
        ApiError::bad_request(
            &unknown_or_missing_field(&text).unwrap_or_else(|| "query".into()),
            text,
        )
    })?;
    let output = q.output.clone().unwrap_or_else(|| "color".into());
    let body = RenderBody {
        scene: q.scene,
        algorithm: q.algorithm,
        camera: q.camera.map(CameraSpec::Named),
        oracles: q.oracles,
        viewport: q.viewport,
        aa: q.aa,
        precision: q.precision,
        texture_filter: q.texture_filter,
        size: q.size,
        outputs: Some(vec![output.clone()]),
        overlays: q.overlays.map(OverlayWords::Text),
    };
    let checked = check(&body, &state).map_err(|mut e| {
        if e.field.as_deref() == Some("outputs") {
            e.field = Some("output".into());
        }
        e
    })?;
    let rendered = run(state, checked).await?;
    let png = rendered.image(&output);
    rendered.out.framebuffer.recycle();
    Ok(([(header::CONTENT_TYPE, "image/png")], png).into_response())
}

/// `GET /api/scenes`: names, triangle counts, cameras, lights and effects of
/// every scene, from the scene files (each loaded once, in parallel, never
/// prepared: listing costs no BVH).
pub async fn scenes(State(state): State<Arc<AppState>>) -> Result<Json<Value>, ApiError> {
    let list = tokio::task::spawn_blocking(move || {
        use rayon::prelude::*;
        let names = state.scene_names()?;
        Ok::<_, ApiError>(
            names
                .par_iter()
                .map(|name| (*state.describe(name)).clone())
                .collect::<Vec<_>>(),
        )
    })
    .await
    .map_err(|e| ApiError::internal(e.to_string()))??;
    Ok(Json(json!({ "scenes": list })))
}

/// `GET /api/algorithms`: every algorithm, what it serves, and whether this
/// server can run it (`available`, with `unavailable_reason` when not).
pub async fn algorithms() -> Result<Json<Value>, ApiError> {
    // Asking about the GPU opens it the first time: off the async runtime.
    let unavailable: Vec<Option<String>> = tokio::task::spawn_blocking(|| {
        AlgorithmId::ALL
            .into_iter()
            .map(continuum::unavailable)
            .collect()
    })
    .await
    .map_err(|e| ApiError::internal(e.to_string()))?;
    let list: Vec<Value> = AlgorithmId::ALL
        .iter()
        .zip(unavailable)
        .map(|(&a, why)| {
            // What the renderer's capability check does not blame `field`
            // for: one setting varied on an otherwise plain request.
            let probe = RenderRequest::new(a, Camera::framing(&Bounds::EMPTY), 64, 64);
            let serves = |field: &str, change: &dyn Fn(&mut RenderRequest)| {
                let mut request = probe.clone();
                change(&mut request);
                continuum::check(&request, None).map_or_else(|e| e.field != field, |_| true)
            };
            json!({
                "id": a.as_str(),
                "available": why.is_none(),
                "unavailable_reason": why,
                "family": a.family(),
                "description": a.description(),
                "viewports": Viewport::KINDS
                    .iter()
                    .filter(|v| serves("viewport", &|r| r.camera.viewport = **v))
                    .map(Viewport::kind)
                    .collect::<Vec<_>>(),
                // Asked of the check, as the other fields are: does it
                // take the algorithm's own example?
                "takes_oracles": (a.oracles_example())
                    .and_then(|example| continuum::Oracles::parse(example).ok())
                    .is_some_and(|o| serves("oracles", &|r| r.oracles = o)),
                "oracles_example": a.oracles_example(),
                "aa": AaMode::all()
                    .iter()
                    .filter(|m| serves("aa", &|r| r.aa = **m))
                    .map(ToString::to_string)
                    .collect::<Vec<_>>(),
                "precisions": Precision::ALL
                    .iter()
                    .filter(|p| serves("precision", &|r| r.precision = **p))
                    .map(|p| p.as_str())
                    .collect::<Vec<_>>(),
            })
        })
        .collect();
    // The overlays any render may draw, and what their colours mean.
    let legend: Vec<Value> = continuum::OVERLAY_LEGEND
        .iter()
        .map(|(meaning, [r, g, b, a])| {
            json!({ "meaning": meaning, "color": format!("#{r:02x}{g:02x}{b:02x}{a:02x}") })
        })
        .collect();
    Ok(Json(json!({
        "algorithms": list,
        "overlays": { "names": Overlays::NAMES, "legend": legend },
    })))
}

/// A JSON body error → 400 naming the unknown or missing field, else `body`.
fn json_error(e: &serde_json::Error) -> ApiError {
    let text = e.to_string();
    let field = unknown_or_missing_field(&text).unwrap_or_else(|| "body".into());
    ApiError::bad_request(&field, format!("invalid request body: {text}"))
}

/// Pulls the field name out of serde's "unknown field `x`" / "missing field `x`".
pub(crate) fn unknown_or_missing_field(text: &str) -> Option<String> {
    for marker in ["unknown field `", "missing field `"] {
        if let Some(start) = text.find(marker) {
            let rest = &text[start + marker.len()..];
            return rest.find('`').map(|end| rest[..end].to_string());
        }
    }
    None
}
