//! The HTTP API: every route, and bad input answered with a 4xx naming the field.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::sync::Arc;

use axum::body::Body;
use axum::http::{Request, StatusCode};
use continuum_server::{AppState, Limits, app};
use tower::ServiceExt;

fn state(limits: Limits) -> Arc<AppState> {
    AppState::new(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes"),
        limits,
    )
}

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime")
}

/// Sends one request through the router; returns status and body bytes.
fn call(state: &Arc<AppState>, req: Request<Body>) -> (StatusCode, Vec<u8>) {
    runtime().block_on(async {
        let res = app(state.clone()).oneshot(req).await.expect("infallible");
        let status = res.status();
        let body = axum::body::to_bytes(res.into_body(), 64 << 20)
            .await
            .expect("body");
        (status, body.to_vec())
    })
}

fn get(state: &Arc<AppState>, uri: &str) -> (StatusCode, Vec<u8>) {
    call(
        state,
        Request::get(uri).body(Body::empty()).expect("request"),
    )
}

fn post(state: &Arc<AppState>, uri: &str, body: &str) -> (StatusCode, serde_json::Value) {
    let (status, bytes) = call(
        state,
        Request::post(uri)
            .header("content-type", "application/json")
            .body(Body::from(body.to_string()))
            .expect("request"),
    );
    (
        status,
        serde_json::from_slice(&bytes)
            .unwrap_or_else(|_| panic!("JSON body: {}", String::from_utf8_lossy(&bytes))),
    )
}

#[test]
fn listings() {
    let s = state(Limits::default());
    let (status, body) = get(&s, "/healthz");
    assert_eq!(
        (status, body.as_slice()),
        (StatusCode::OK, b"ok\n".as_slice())
    );
    let (status, body) = get(&s, "/api/algorithms");
    assert_eq!(status, StatusCode::OK);
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    let ids: Vec<&str> = doc["algorithms"]
        .as_array()
        .expect("list")
        .iter()
        .filter_map(|a| a["id"].as_str())
        .collect();
    let expected: Vec<&str> = continuum::AlgorithmId::ALL
        .iter()
        .map(|a| a.as_str())
        .collect();
    assert_eq!(ids, expected);
}

#[test]
fn web_page_and_metrics() {
    let s = state(Limits::default());
    let (status, page) = get(&s, "/");
    assert_eq!(status, StatusCode::OK);
    let page = String::from_utf8(page).expect("utf-8");
    assert!(page.contains("<title>continuum</title>") && page.contains("/api/render"));
    get(
        &s,
        "/api/render.png?scene=box&algorithm=3dr-full&size=16x16",
    );
    get(&s, "/api/render.png?scene=box&algorithm=nope");
    let (status, text) = get(&s, "/metrics");
    assert_eq!(status, StatusCode::OK);
    let text = String::from_utf8(text).expect("utf-8");
    for line in [
        "continuum_requests_total{route=\"/api/render.png\",status=\"200\"} 1",
        "continuum_requests_total{route=\"/api/render.png\",status=\"400\"} 1",
        "continuum_render_seconds_count{algorithm=\"3dr-full\"} 1",
        "continuum_renders_in_flight 0",
        "continuum_scene_cache_size 1",
    ] {
        assert!(text.contains(line), "missing {line} in\n{text}");
    }
}

#[test]
fn render_json_and_png() {
    let s = state(Limits::default());
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "raycast", "camera": "outside", "size": "64x48", "outputs": ["color", "edge_evals"] }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
    assert_eq!(doc["algorithm"], "raycast");
    assert!(
        doc["stats"]["coverage_histogram"]["many"]
            .as_u64()
            .expect("count")
            > 0,
        "front and back faces"
    );
    for key in ["color", "edge_evals"] {
        assert!(
            doc["images"][key].as_str().expect("base64").len() > 100,
            "{key}"
        );
    }
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "3dr-brute", "size": "32x32", "camera": { "eye": [2, 1, 2], "target": [0, 0, 0], "fov_y": 50 } }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
    let (status, png) = get(
        &s,
        "/api/render.png?scene=box&algorithm=2dr-brute&size=32x24",
    );
    assert_eq!(status, StatusCode::OK);
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn bad_input_is_a_4xx_naming_the_field() {
    let s = state(Limits {
        max_pixels: 400_000,
        ..Limits::default()
    });
    let cases = [
        (r#"{ "scene": "nosuch", "algorithm": "raycast" }"#, "scene"),
        (r#"{ "scene": "box", "algorithm": "zbuffer" }"#, "algorithm"),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "size": "0x10" }"#,
            "size",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "size": "1000x1000" }"#,
            "size",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "viewport": "fisheye" }"#,
            "viewport",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "aa": "msaa:99" }"#,
            "aa",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "camera": "nosuch" }"#,
            "camera",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "camera": { "eye": [1e39, 0, 0], "target": [0, 0, 0] } }"#,
            "camera",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "outputs": ["x-ray"] }"#,
            "outputs",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "colour": "red" }"#,
            "colour",
        ),
        (r#"{ "algorithm": "raycast" }"#, "scene"),
        (r#"{ "scene": "box", "algorithm": "#, "body"),
    ];
    for (body, field) in cases {
        let (status, doc) = post(&s, "/api/render", body);
        assert!(status.is_client_error(), "{body}: {status}");
        assert_eq!(doc["field"], field, "{body}: {doc}");
        assert!(doc["error"].as_str().is_some_and(|e| !e.is_empty()));
    }
    let (status, body) = get(&s, "/api/render.png?scene=box&algorithm=raycast&zoom=2");
    assert_eq!(status, StatusCode::BAD_REQUEST);
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    assert_eq!(doc["field"], "zoom", "{doc}");
    let (status, _) = get(&s, "/api/scenes/../../etc/passwd");
    assert_eq!(status, StatusCode::NOT_FOUND);
}

#[test]
fn overload_answers_503_and_the_server_keeps_serving() {
    let s = state(Limits {
        max_concurrent_renders: 1,
        ..Limits::default()
    });
    // Hold the only render slot, as a long render would.
    let held = s.renders_for_test().try_acquire_owned().expect("free slot");
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "raycast", "size": "16x16" }"#,
    );
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{doc}");
    drop(held);
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "raycast", "size": "16x16" }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
}

#[test]
fn serves_over_a_real_socket() {
    let rt = runtime();
    let s = state(Limits::default());
    let addr = rt.block_on(async {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
            .await
            .expect("bind");
        let addr = listener.local_addr().expect("addr");
        tokio::spawn(async move { axum::serve(listener, app(s)).await });
        addr
    });
    let mut stream = std::net::TcpStream::connect(addr).expect("connect");
    stream
        .write_all(b"GET /api/render.png?scene=sphere&algorithm=3dr-brute&size=40x30 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .expect("send");
    let mut response = Vec::new();
    stream.read_to_end(&mut response).expect("read");
    let text = String::from_utf8_lossy(&response);
    assert!(
        text.starts_with("HTTP/1.1 200"),
        "{}",
        &text[..text.len().min(200)]
    );
    assert!(text.contains("content-type: image/png"));
    assert!(response.windows(4).any(|w| w == b"\x89PNG"));
}

fn upload(state: &Arc<AppState>, query: &str, body: Vec<u8>) -> (StatusCode, serde_json::Value) {
    let (status, bytes) = call(
        state,
        Request::post(format!("/api/scenes{query}"))
            .header("content-type", "model/gltf-binary")
            .body(Body::from(body))
            .expect("request"),
    );
    (
        status,
        serde_json::from_slice(&bytes)
            .unwrap_or_else(|_| panic!("JSON body: {}", String::from_utf8_lossy(&bytes))),
    )
}

fn box_glb() -> Vec<u8> {
    std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets/Box.glb"))
        .expect("Box.glb")
}

#[test]
fn uploads_are_validated_kept_and_rendered() {
    let s = state(Limits {
        max_body_bytes: 64 << 10,
        max_upload_triangles: 100,
        ..Limits::default()
    });
    let (status, doc) = upload(&s, "?name=my-box", box_glb());
    assert_eq!(status, StatusCode::CREATED, "{doc}");
    assert_eq!(
        (doc["scene"].as_str(), doc["triangles"].as_u64()),
        (Some("my-box"), Some(12))
    );
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "my-box", "algorithm": "3dr-full", "size": "32x32" }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
    let (_, listing) = get(&s, "/api/scenes");
    assert!(String::from_utf8_lossy(&listing).contains("my-box"));
    // A default name from the content.
    let (status, doc) = upload(&s, "", box_glb());
    assert_eq!(status, StatusCode::CREATED, "{doc}");
    assert!(
        doc["scene"]
            .as_str()
            .is_some_and(|n| n.starts_with("upload-"))
    );

    let cases: Vec<(&str, Vec<u8>, StatusCode, &str)> = vec![
        (
            "",
            b"not a glb at all".to_vec(),
            StatusCode::BAD_REQUEST,
            "file",
        ),
        ("", Vec::new(), StatusCode::BAD_REQUEST, "file"),
        (
            "?name=Bad%20Name",
            box_glb(),
            StatusCode::BAD_REQUEST,
            "name",
        ),
        ("?name=bunny", box_glb(), StatusCode::BAD_REQUEST, "name"),
        ("?colour=red", box_glb(), StatusCode::BAD_REQUEST, "colour"),
        (
            "",
            vec![0u8; 100 << 10],
            StatusCode::PAYLOAD_TOO_LARGE,
            "body",
        ),
        (
            "",
            std::fs::read(
                PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                    .join("../scenes/assets/OrientationTest.glb"),
            )
            .expect("glb"),
            StatusCode::PAYLOAD_TOO_LARGE,
            "file",
        ),
    ];
    for (query, body, expected, field) in cases {
        let (status, doc) = upload(&s, query, body);
        assert_eq!(status, expected, "{query}: {doc}");
        assert_eq!(doc["field"], field, "{query}: {doc}");
    }
}

#[test]
fn slow_renders_time_out_with_504() {
    let s = state(Limits {
        render_timeout: std::time::Duration::from_nanos(1),
        ..Limits::default()
    });
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "teapots", "algorithm": "2dr-brute", "size": "640x480" }"#,
    );
    assert_eq!(status, StatusCode::GATEWAY_TIMEOUT, "{doc}");
}
