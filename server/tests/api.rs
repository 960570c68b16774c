//! The HTTP API: every route, and bad input answered with a 4xx naming the field.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use axum::http::StatusCode;
use continuum_server::{AppState, Limits, app};

/// The service on a real socket (127.0.0.1, a free port), for one test.
struct Server {
    _runtime: tokio::runtime::Runtime,
    addr: SocketAddr,
    state: Arc<AppState>,
}

fn state(limits: Limits) -> Server {
    let state = AppState::new(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes"),
        limits,
    );
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");
    let app_state = state.clone();
    let addr = runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
            .await
            .expect("bind");
        let addr = listener.local_addr().expect("addr");
        tokio::spawn(async move { axum::serve(listener, app(app_state)).await });
        addr
    });
    Server {
        _runtime: runtime,
        addr,
        state,
    }
}

/// One HTTP/1.1 request over a fresh connection. Bodies are announced with
/// `Expect: 100-continue` and only sent once the server asks for them, as real
/// clients do for uploads.
fn http(
    server: &Server,
    method: &str,
    path: &str,
    content_type: &str,
    body: &[u8],
) -> (StatusCode, Vec<u8>) {
    let (status, _, body) = http_with_headers(server, method, path, content_type, body);
    (status, body)
}

/// [`http`], also returning the response's header lines (lower case).
fn http_with_headers(
    server: &Server,
    method: &str,
    path: &str,
    content_type: &str,
    body: &[u8],
) -> (StatusCode, Vec<String>, Vec<u8>) {
    let mut stream = TcpStream::connect(server.addr).expect("connect");
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .expect("timeout");
    let mut head = format!("{method} {path} HTTP/1.1\r\nHost: test\r\nConnection: close\r\n");
    if !body.is_empty() {
        head.push_str(&format!(
            "Content-Type: {content_type}\r\nContent-Length: {}\r\nExpect: 100-continue\r\n",
            body.len()
        ));
    }
    head.push_str("\r\n");
    stream.write_all(head.as_bytes()).expect("send head");
    let mut reader = BufReader::new(stream.try_clone().expect("clone"));
    let mut status_line = String::new();
    reader.read_line(&mut status_line).expect("status line");
    if status_line.starts_with("HTTP/1.1 100") {
        let mut blank = String::new();
        reader.read_line(&mut blank).expect("blank line");
        stream.write_all(body).expect("send body");
        status_line.clear();
        reader.read_line(&mut status_line).expect("status line");
    }
    let code: u16 = status_line
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status code");
    let mut headers = Vec::new();
    loop {
        let mut line = String::new();
        reader.read_line(&mut line).expect("header");
        if line == "\r\n" || line.is_empty() {
            break;
        }
        headers.push(line.to_ascii_lowercase());
    }
    let mut rest = Vec::new();
    reader.read_to_end(&mut rest).expect("body");
    let body = if headers
        .iter()
        .any(|h| h.starts_with("transfer-encoding: chunked"))
    {
        dechunk(&rest)
    } else {
        rest
    };
    (StatusCode::from_u16(code).expect("status"), headers, body)
}

fn dechunk(mut data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let end = data
            .windows(2)
            .position(|w| w == b"\r\n")
            .expect("chunk size line");
        let size =
            usize::from_str_radix(std::str::from_utf8(&data[..end]).expect("hex").trim(), 16)
                .expect("chunk size");
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&data[end + 2..end + 2 + size]);
        data = &data[end + 2 + size + 2..];
    }
}

fn get(server: &Server, uri: &str) -> (StatusCode, Vec<u8>) {
    http(server, "GET", uri, "", b"")
}

fn post(server: &Server, uri: &str, body: &str) -> (StatusCode, serde_json::Value) {
    let (status, bytes) = http(server, "POST", uri, "application/json", body.as_bytes());
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
    let (status, body) = get(&s, "/api/scenes");
    assert_eq!(status, StatusCode::OK);
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    let bunny = doc["scenes"]
        .as_array()
        .expect("list")
        .iter()
        .find(|s| s["name"] == "bunny")
        .expect("bunny");
    assert_eq!(bunny["triangles"], 69_451);
    assert!(
        bunny["cameras"]
            .as_array()
            .expect("cameras")
            .iter()
            .any(|c| c["name"] == "front" && c["eye"].is_array())
    );
    assert!(bunny["effects"].is_array());
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
        "continuum_render_queue_depth 0",
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
    // Extreme but finite cameras render (nothing, or something) instead of failing.
    for algorithm in continuum::AlgorithmId::ALL {
        for camera in [
            r#"{ "eye": [3e37, -3e37, 1e37], "target": [0, 0, 0], "fov_y": 179.9 }"#,
            r#"{ "eye": [1e-30, 0, 0], "target": [2e-30, 0, 0], "fov_y": 0.001, "near": 1e-38 }"#,
        ] {
            let body = format!(
                r#"{{ "scene": "sphere", "algorithm": "{algorithm}", "size": "24x16", "camera": {camera} }}"#
            );
            let (status, doc) = post(&s, "/api/render", &body);
            assert_eq!(status, StatusCode::OK, "{algorithm} {camera}: {doc}");
        }
    }
    // Anti-aliasing: the mode comes back with its sample counts; too many
    // samples per pixel for the server's limit is a 400 naming `aa`.
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "3dr-bin", "size": "32x24", "aa": "csaa:16x4" }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
    assert_eq!(doc["aa"], "csaa:16x4");
    assert_eq!(doc["stats"]["samples_per_pixel"], 16);
    assert_eq!(doc["stats"]["stored_samples_per_pixel"], 4);
    let small = state(Limits {
        max_samples_per_pixel: 16,
        ..Limits::default()
    });
    let (status, doc) = post(
        &small,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "3dr-bin", "size": "32x24", "aa": "ssaa:64" }"#,
    );
    assert_eq!(status, StatusCode::BAD_REQUEST, "{doc}");
    assert_eq!(doc["field"], "aa");
    // Within samples per pixel but over the samples of one render.
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "3dr-bin", "size": "2560x1600", "aa": "ssaa:64" }"#,
    );
    assert_eq!(status, StatusCode::BAD_REQUEST, "{doc}");
    assert_eq!(doc["field"], "aa");
    assert!(
        doc["error"].as_str().is_some_and(|e| e.contains("samples")),
        "{doc}"
    );
    let (status, png) = get(
        &s,
        "/api/render.png?scene=box&algorithm=2dr-brute&size=32x24&aa=msaa:4",
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
            r#"{ "scene": "box", "algorithm": "3dr-full", "viewport": "latlong" }"#,
            "viewport",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "viewport": "orthographic:-1" }"#,
            "viewport",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "viewport": "fisheye" }"#,
            "viewport",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "overlays": ["frusta", "heat"] }"#,
            "overlays",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "overlays": 3 }"#,
            "overlays",
        ),
        (
            r#"{ "scene": "box", "algorithm": "2dr-bin", "precision": "f64" }"#,
            "precision",
        ),
        (
            r#"{ "scene": "box", "algorithm": "raycast", "precision": "f16" }"#,
            "precision",
        ),
        (
            r#"{ "scene": "box", "algorithm": "gpu-raster", "aa": "msaa:4" }"#,
            "aa",
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
fn a_full_queue_answers_503_and_queued_renders_wait_their_turn() {
    let s = Arc::new(state(Limits {
        max_concurrent_renders: 1,
        max_queued_renders: 1,
        ..Limits::default()
    }));
    let held = s
        .state
        .renders_for_test()
        .try_acquire_owned()
        .expect("free slot");
    let body = r#"{ "scene": "box", "algorithm": "raycast", "size": "16x16" }"#;
    let queued = {
        let s = s.clone();
        std::thread::spawn(move || post(&s, "/api/render", body).0)
    };
    // Wait until that request is in the queue, then one more is refused.
    let start = std::time::Instant::now();
    loop {
        let (_, text) = get(&s, "/metrics");
        if String::from_utf8_lossy(&text).contains("continuum_render_queue_depth 1") {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "the request never queued"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let (status, doc) = post(&s, "/api/render", body);
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{doc}");
    drop(held);
    assert_eq!(queued.join().expect("queued request"), StatusCode::OK);
}

#[test]
fn overload_answers_503_and_the_server_keeps_serving() {
    let s = state(Limits {
        max_concurrent_renders: 1,
        max_queued_renders: 0,
        ..Limits::default()
    });
    // Hold the only render slot, as a long render would.
    let held = s
        .state
        .renders_for_test()
        .try_acquire_owned()
        .expect("free slot");
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

fn upload(server: &Server, query: &str, body: &[u8]) -> (StatusCode, serde_json::Value) {
    let (status, bytes) = http(
        server,
        "POST",
        &format!("/api/scenes{query}"),
        "model/gltf-binary",
        body,
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
    let (status, doc) = upload(&s, "?name=my-box", &box_glb());
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
    let (status, doc) = upload(&s, "", &box_glb());
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
        let (status, doc) = upload(&s, query, &body);
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

#[test]
fn a_render_answered_504_is_cancelled_and_frees_its_slot() {
    // One slot; a 1 s timeout; room for a render of a billion samples.
    let s = state(Limits {
        max_concurrent_renders: 1,
        max_queued_renders: 1,
        render_timeout: Duration::from_secs(1),
        max_samples: 1 << 31,
        ..Limits::default()
    });
    for scene in ["teapots", "box"] {
        s.state
            .prepared(scene)
            .expect("prepared ahead, outside the timeout");
    }
    // Far more than a second of work, uncancelled: a million triangles at
    // 2560x1600 with 64 samples per pixel (262M samples).
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "teapots", "algorithm": "3dr-brute", "size": "2560x1600", "aa": "ssaa:64" }"#,
    );
    assert_eq!(status, StatusCode::GATEWAY_TIMEOUT, "{doc}");
    assert_eq!(doc["field"], "timeout", "{doc}");
    // The cancelled render stops at its next tile and gives its slot back:
    // within a second here, polled for up to five so a loaded machine does
    // not fail it (the render itself would take tens of seconds).
    let slots = s.state.renders_for_test();
    let answered = std::time::Instant::now();
    while slots.available_permits() == 0 {
        assert!(
            answered.elapsed() < Duration::from_secs(5),
            "the cancelled render still holds its slot"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let (status, doc) = post(
        &s,
        "/api/render",
        r#"{ "scene": "box", "algorithm": "raycast", "size": "16x16" }"#,
    );
    assert_eq!(status, StatusCode::OK, "{doc}");
}

#[test]
fn every_error_status_answers_error_and_field_as_json() {
    let s = state(Limits {
        max_body_bytes: 1 << 10,
        render_timeout: Duration::from_nanos(1),
        ..Limits::default()
    });
    let big = vec![b'x'; 4 << 10];
    let render = br#"{ "scene": "box", "algorithm": "raycast", "size": "16x16" }"#;
    // Slow enough never to beat the 1 ns timeout (a 16x16 box render can).
    let slow = br#"{ "scene": "teapots", "algorithm": "2dr-brute", "size": "640x480" }"#;
    /// Method, path, content type, body → status and the field named.
    type Case<'a> = (&'a str, &'a str, &'a str, &'a [u8], StatusCode, &'a str);
    let cases: [Case; 7] = [
        (
            "GET",
            "/api/render.png?scene=nosuch&algorithm=raycast",
            "",
            b"",
            StatusCode::BAD_REQUEST,
            "scene",
        ),
        (
            "GET",
            "/no/such/route",
            "",
            b"",
            StatusCode::NOT_FOUND,
            "path",
        ),
        (
            "GET",
            "/api/render",
            "",
            b"",
            StatusCode::METHOD_NOT_ALLOWED,
            "method",
        ),
        (
            "POST",
            "/api/render",
            "application/json",
            &big,
            StatusCode::PAYLOAD_TOO_LARGE,
            "body",
        ),
        (
            "POST",
            "/api/render",
            "text/plain",
            render,
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "content-type",
        ),
        (
            "POST",
            "/api/render",
            "",
            b"",
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "content-type",
        ),
        (
            "POST",
            "/api/render",
            "application/json; charset=utf-8",
            slow,
            StatusCode::GATEWAY_TIMEOUT,
            "timeout",
        ),
    ];
    for (method, path, kind, body, expected, field) in cases {
        let (status, headers, bytes) = http_with_headers(&s, method, path, kind, body);
        let text = String::from_utf8_lossy(&bytes);
        assert_eq!(status, expected, "{method} {path}: {text}");
        assert!(
            headers
                .iter()
                .any(|h| h.starts_with("content-type: application/json")),
            "{method} {path}: {headers:?}"
        );
        let doc: serde_json::Value = serde_json::from_slice(&bytes).expect("a JSON body");
        assert_eq!(doc["field"], field, "{method} {path}: {doc}");
        assert!(
            doc["error"].as_str().is_some_and(|e| !e.is_empty()),
            "{doc}"
        );
    }
}

#[test]
fn listing_scenes_prepares_none() {
    let s = state(Limits::default());
    let (status, body) = get(&s, "/api/scenes");
    assert_eq!(status, StatusCode::OK);
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    let listed = doc["scenes"].as_array().expect("list");
    let builtin =
        continuum::scene::builtin_names(&s.state.scenes_dir).expect("the scenes folder lists");
    assert!(builtin.len() >= 12, "{builtin:?}");
    assert_eq!(listed.len(), builtin.len());
    for scene in listed {
        assert!(scene["error"].is_null(), "{scene}");
        assert!(
            scene["triangles"].as_u64().is_some_and(|t| t > 0),
            "{scene}"
        );
        assert!(
            !scene["cameras"].as_array().expect("cameras").is_empty(),
            "{scene}"
        );
    }
    let teapots = listed
        .iter()
        .find(|s| s["name"] == "teapots")
        .expect("teapots");
    assert_eq!(teapots["triangles"], 1_048_576);
    assert_eq!(s.state.prepared_count(), 0, "listing prepared a scene");
}

#[test]
fn algorithms_say_whether_this_server_runs_them() {
    let s = state(Limits::default());
    let (status, body) = get(&s, "/api/algorithms");
    assert_eq!(status, StatusCode::OK);
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    let list = doc["algorithms"].as_array().expect("list");
    assert_eq!(list.len(), continuum::AlgorithmId::ALL.len());
    for a in list {
        let id = a["id"].as_str().expect("id");
        let available = a["available"].as_bool().expect("available");
        let algorithm: continuum::AlgorithmId = id.parse().expect("an id");
        assert_eq!(
            available,
            continuum::unavailable(algorithm).is_none(),
            "{a}"
        );
        assert_eq!(a["unavailable_reason"].is_null(), available, "{a}");
    }
}

/// `/api/algorithms` gives each algorithm that takes oracles an example
/// setting, which renders; the others (`2dr-scanline`, the GPU) are listed
/// as taking none, and a render of theirs with oracles is a 400 naming
/// `oracles`.
#[test]
fn every_oracles_example_renders() {
    let s = state(Limits::default());
    let (_, body) = get(&s, "/api/algorithms");
    let doc: serde_json::Value = serde_json::from_slice(&body).expect("json");
    let list = doc["algorithms"].as_array().expect("list");
    let (mut rendered, mut refused) = (0, 0);
    for a in list {
        let id = a["id"].as_str().expect("id");
        let takes = a["takes_oracles"].as_bool().expect("takes_oracles");
        assert_eq!(takes, a["oracles_example"].is_string(), "{a}");
        let oracles = a["oracles_example"].as_str().unwrap_or("early_z=on");
        let body = format!(
            r#"{{ "scene": "box", "algorithm": "{id}", "size": "16x16", "oracles": "{oracles}" }}"#
        );
        let (status, answer) = post(&s, "/api/render", &body);
        if takes {
            assert_eq!(status, StatusCode::OK, "{id} with {oracles}: {answer}");
            rendered += 1;
        } else {
            assert_eq!(status, StatusCode::BAD_REQUEST, "{id}: {answer}");
            assert_eq!(answer["field"], "oracles", "{id}: {answer}");
            refused += 1;
        }
    }
    // Every CPU algorithm but `2dr-scanline` takes oracles.
    assert_eq!((rendered, refused), (9, list.len() - 9));
}

/// Overlays over HTTP: as a list or as words, drawn over every image asked
/// for (the images change, the render's hashes do not), and listed with
/// their legend by `/api/algorithms`.
#[test]
fn overlays_are_drawn_over_the_images() {
    let s = state(Limits::default());
    let body = |overlays: &str| {
        format!(
            r#"{{ "scene": "teapots", "algorithm": "3dr-frustum-split", "size": "160x120", "outputs": ["color", "edge_evals"] {overlays} }}"#
        )
    };
    let (status, plain) = post(&s, "/api/render", &body(""));
    assert_eq!(status, StatusCode::OK, "{plain}");
    for overlays in [
        r#", "overlays": ["frusta", "tiles"]"#,
        r#", "overlays": "frusta,tiles""#,
    ] {
        let (status, drawn) = post(&s, "/api/render", &body(overlays));
        assert_eq!(status, StatusCode::OK, "{drawn}");
        assert_eq!(drawn["hashes"], plain["hashes"]);
        for key in ["color", "edge_evals"] {
            assert_ne!(
                drawn["images"][key], plain["images"][key],
                "{overlays}: {key}"
            );
        }
    }
    let (status, png) = get(
        &s,
        "/api/render.png?scene=teapots&algorithm=3dr-frustum-split&size=160x120&overlays=frusta",
    );
    assert_eq!(status, StatusCode::OK);
    assert!(png.starts_with(b"\x89PNG"));
    let (_, listing) = get(&s, "/api/algorithms");
    let listing: serde_json::Value = serde_json::from_slice(&listing).unwrap();
    let names = listing["overlays"]["names"].as_array().expect("names");
    assert_eq!(names.len(), 4);
    assert!(
        listing["overlays"]["legend"]
            .as_array()
            .expect("legend")
            .len()
            >= 8
    );
}
