//! The one error type of the API: a status, a message and the request field at fault.

use axum::Json;
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use continuum::FieldError;

#[derive(Debug, Clone, PartialEq)]
pub struct ApiError {
    pub status: StatusCode,
    pub error: String,
    pub field: Option<String>,
}

impl ApiError {
    pub fn bad_request(field: &str, error: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::BAD_REQUEST,
            error: error.into(),
            field: Some(field.to_string()),
        }
    }

    pub fn not_found(field: &str, error: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::NOT_FOUND,
            error: error.into(),
            field: Some(field.to_string()),
        }
    }

    pub fn overloaded() -> ApiError {
        ApiError {
            status: StatusCode::SERVICE_UNAVAILABLE,
            error: "all render workers are busy; retry shortly".into(),
            field: Some("queue".into()),
        }
    }

    pub fn with_status(
        status: StatusCode,
        field: Option<&str>,
        error: impl Into<String>,
    ) -> ApiError {
        ApiError {
            status,
            error: error.into(),
            field: field.map(str::to_string),
        }
    }

    /// A request body that could not be read (too large, cut off).
    pub fn body(rejection: &axum::extract::rejection::BytesRejection) -> ApiError {
        ApiError::with_status(rejection.status(), Some("body"), rejection.body_text())
    }

    pub fn internal(error: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::INTERNAL_SERVER_ERROR,
            error: error.into(),
            field: Some("server".into()),
        }
    }

    /// A route that exists, asked with another method.
    pub fn method_not_allowed() -> ApiError {
        ApiError::with_status(
            StatusCode::METHOD_NOT_ALLOWED,
            Some("method"),
            "this route does not take that method (GET reads, POST renders or uploads)",
        )
    }

    /// Checks that a JSON endpoint's body says it is JSON (`application/json`,
    /// parameters such as `charset` allowed).
    pub fn require_json(headers: &axum::http::HeaderMap) -> Result<(), ApiError> {
        let kind = headers
            .get(header::CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .unwrap_or("");
        let essence = kind.split(';').next().unwrap_or("").trim();
        if essence.eq_ignore_ascii_case("application/json") {
            Ok(())
        } else {
            Err(ApiError::with_status(
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                Some("content-type"),
                format!(
                    "the body must be JSON sent as content-type application/json, not '{kind}'"
                ),
            ))
        }
    }
}

impl From<FieldError> for ApiError {
    fn from(e: FieldError) -> Self {
        ApiError::bad_request(e.field, e.to_string())
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = Json(serde_json::json!({ "error": self.error, "field": self.field }));
        if self.status == StatusCode::SERVICE_UNAVAILABLE {
            (self.status, [(header::RETRY_AFTER, "1")], body).into_response()
        } else {
            (self.status, body).into_response()
        }
    }
}
