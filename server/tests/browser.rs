//! The web page in headless Chromium, driven over WebDriver (chromedriver):
//! load, render, switch to the edge-evaluation map, open the compare view, and
//! save a screenshot. Needs Debian's `chromium` and `chromium-driver` (`.ci/run`
//! installs them); without them this test fails, loudly.

use std::net::TcpListener;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use continuum_server::{AppState, Limits, app};
use fantoccini::{ClientBuilder, Locator};
use serde_json::json;

/// Kills chromedriver when the test ends, however it ends.
struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .expect("bind")
        .local_addr()
        .expect("addr")
        .port()
}

fn start_chromedriver() -> (Driver, u16) {
    let port = free_port();
    let child = Command::new("chromedriver")
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| {
            panic!("cannot start chromedriver ({e}): install Debian's chromium and chromium-driver")
        });
    let start = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "chromedriver did not start listening"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    (Driver(child), port)
}

#[test]
fn the_page_renders_switches_maps_and_compares() {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");
    let state = AppState::new(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes"),
        Limits::default(),
    );
    let addr = runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
            .await
            .expect("bind");
        let addr = listener.local_addr().expect("addr");
        tokio::spawn(async move { axum::serve(listener, app(state)).await });
        addr
    });
    let (_driver, port) = start_chromedriver();
    let profile = std::env::temp_dir().join(format!("continuum-chromium-{}", std::process::id()));
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));

    runtime.block_on(async move {
        let mut caps = serde_json::Map::new();
        caps.insert(
            "goog:chromeOptions".into(),
            json!({
                "binary": "/usr/bin/chromium",
                "args": ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
                         "--disable-background-networking", "--disable-component-update", "--disable-sync",
                         "--window-size=1400,1000", format!("--user-data-dir={}", profile.display())],
            }),
        );
        let connector = hyper_util::client::legacy::connect::HttpConnector::new();
        let client = ClientBuilder::new(connector)
            .capabilities(caps)
            .connect(&format!("http://127.0.0.1:{port}"))
            .await
            .expect("a WebDriver session with headless Chromium");

        let text_of = |id: &'static str| {
            let client = client.clone();
            async move { client.find(Locator::Id(id)).await.expect(id).text().await.expect("text") }
        };
        let wait_until = |what: &'static str, id: &'static str, needle: &'static str| {
            let client = client.clone();
            async move {
                let start = Instant::now();
                loop {
                    let text = client.find(Locator::Id(id)).await.expect(id).text().await.unwrap_or_default();
                    if text.contains(needle) {
                        return text;
                    }
                    let error = client.find(Locator::Id("error")).await.expect("error").text().await.unwrap_or_default();
                    assert!(error.is_empty(), "{what}: the page shows an error: {error}");
                    assert!(start.elapsed() < Duration::from_secs(60), "{what}: '{needle}' never appeared in #{id}: {text}");
                    tokio::time::sleep(Duration::from_millis(100)).await;
                }
            }
        };

        // 1. Load and render the first scene.
        client.goto(&format!("http://{addr}/")).await.expect("load the page");
        let stats = wait_until("first render", "stats", "total ms").await;
        assert!(stats.contains("edge evaluations") && stats.contains("triangle setups"), "{stats}");
        let src = client.find(Locator::Id("image")).await.expect("image").attr("src").await.expect("src").unwrap_or_default();
        assert!(src.starts_with("data:image/png;base64,"), "{}", &src[..src.len().min(60)]);

        // 2. The edge-evaluation map and its legend.
        client.find(Locator::Css("button[data-view=edge_evals]")).await.expect("button").click().await.expect("click");
        let legend = client.find(Locator::Id("legend")).await.expect("legend");
        assert!(legend.is_displayed().await.expect("displayed"), "the heat-map legend shows");
        assert!(!text_of("legend-max").await.is_empty());
        let heat = client.find(Locator::Id("image")).await.expect("image").attr("src").await.expect("src").unwrap_or_default();
        assert_ne!(heat, src, "the image switched to the heat map");
        std::fs::write(shots.join("browser-heat-map.png"), client.screenshot().await.expect("screenshot")).expect("save");

        // 3. The oracles field follows the algorithm: its example as the
        // placeholder, off for an algorithm that takes none.
        let oracles_a = || async { client.find(Locator::Id("oracles-a")).await.expect("oracles-a") };
        for (algorithm, placeholder, enabled) in [
            ("raycast", "e.g. packet=4", true),
            ("3dr-full", "e.g. split=16,occluded=off", true),
            ("2dr-scanline", "this algorithm takes none", false),
        ] {
            client.find(Locator::Id("algorithm-a")).await.expect("algorithm-a")
                .select_by_value(algorithm).await.expect("select the algorithm");
            let field = oracles_a().await;
            let shown = field.attr("placeholder").await.expect("placeholder");
            assert_eq!(shown.as_deref(), Some(placeholder), "{algorithm}");
            assert_eq!(field.is_enabled().await.expect("enabled"), enabled, "{algorithm}");
        }
        client.find(Locator::Id("algorithm-a")).await.expect("algorithm-a")
            .select_by_value("3dr-full").await.expect("select 3dr-full");

        // 4. Effects: a texture filter on the checkerboard, then the glass panes;
        // the stats table lists what each effect cost.
        client.find(Locator::Css("button[data-view=color]")).await.expect("button").click().await.expect("click");
        client.find(Locator::Id("texture-filter")).await.expect("filter").send_keys("anisotropic:8\n").await.expect("type");
        client.find(Locator::Id("scene")).await.expect("scene").select_by_value("checker").await.expect("select checker");
        let stats = wait_until("checker", "stats", "lookups").await;
        assert!(stats.contains("textures"), "{stats}");
        client.find(Locator::Id("scene")).await.expect("scene").select_by_value("pane").await.expect("select pane");
        let stats = wait_until("pane", "stats", "fragments").await;
        assert!(stats.contains("transparency") && stats.contains("shadows"), "{stats}");
        std::fs::write(shots.join("browser-pane.png"), client.screenshot().await.expect("screenshot")).expect("save");

        // 5. Downloads and "copy as curl" for the last render.
        let downloads = text_of("downloads").await;
        assert!(downloads.contains("color.png") && downloads.contains("statistics.json"), "{downloads}");
        client.find(Locator::Id("copy-curl")).await.expect("copy as curl").click().await.expect("click");
        let curl = wait_until("copy as curl", "curl", "curl -X POST").await;
        assert!(curl.contains("/api/render") && curl.contains("\"scene\":\"pane\""), "{curl}");

        // 6. Upload a .glb through the page and render it.
        let glb = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets/Box.glb");
        let glb = glb.canonicalize().expect("Box.glb");
        client.find(Locator::Id("upload-name")).await.expect("name").send_keys("my-box").await.expect("type");
        client.find(Locator::Id("upload-file")).await.expect("file input")
            .send_keys(glb.to_str().expect("utf-8 path")).await.expect("choose the file");
        client.find(Locator::Id("upload")).await.expect("upload").click().await.expect("click");
        wait_until("upload", "upload-status", "my-box: 12 triangles").await;
        let scene = client.find(Locator::Id("scene")).await.expect("scene").prop("value").await.expect("value");
        assert_eq!(scene.as_deref(), Some("my-box"));
        wait_until("the uploaded scene's render", "stats", "total ms").await;
        wait_until("the uploaded scene's downloads", "downloads", "my-box-").await;

        // 7. The compare view: two images, their difference, the timing bars.
        client.find(Locator::Id("show-compare")).await.expect("compare").click().await.expect("click");
        let caption = wait_until("compare", "cap-diff", " differ").await;
        assert!(caption.contains("difference"), "{caption}");
        let bars = text_of("bars").await;
        assert!(bars.contains("total A") && bars.contains("total B"), "{bars}");
        let png = client.screenshot().await.expect("screenshot");
        std::fs::write(shots.join("browser-compare.png"), &png).expect("save");
        assert_eq!(&png[1..4], b"PNG");
        client.close().await.expect("close the session");
    });
}
