#pragma once
// The OpenAPI 3.1 document of the REST API (daemon/service/openapi.json, built into the binary
// with the project's version), served at GET /v1/openapi.json.

namespace boxd {

// Returns the document's JSON text.
const char* OpenApiDocument();

}  // namespace boxd
