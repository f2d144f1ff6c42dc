// The REST routes the server answers, as (method, path pattern with {id}); the test that keeps
// core/server/openapi.json honest compares the two.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace gbdcs::server {

std::vector<std::pair<std::string, std::string>> api_routes();

}  // namespace gbdcs::server
