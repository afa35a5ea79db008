// Tests of which file robotalk-web serves for a URL: nothing outside its folders.
#include "web_files.h"

#include <gtest/gtest.h>

namespace robotalk::web {
namespace {

WebOptions Options() {
  WebOptions o;
  o.www_dir = "/srv/www";
  o.node_modules_dir = "/srv/nm";
  o.urdf["pioneer"] = "/robots/pioneer/p.urdf";
  return o;
}

std::string Resolve(std::string_view target) {
  const auto p = ResolveWebPath(target, Options());
  return p ? p->string() : "(refused)";
}

TEST(ResolveWebPath, MapsThePageModulesAndUrdfFolders) {
  EXPECT_EQ(Resolve("/"), "/srv/www/index.html");
  EXPECT_EQ(Resolve("/app.js?v=2"), "/srv/www/app.js");
  EXPECT_EQ(Resolve("/modules/three/build/three.module.js"), "/srv/nm/three/build/three.module.js");
  EXPECT_EQ(Resolve("/modules/urdf-loader/src/URDFLoader.js"), "/srv/nm/urdf-loader/src/URDFLoader.js");
  EXPECT_EQ(Resolve("/urdf/pioneer/p.urdf"), "/robots/pioneer/p.urdf");
}

TEST(ResolveWebPath, RefusesEverythingElse) {
  for (const char* bad :
       {"", "app.js", "/../etc/passwd", "/modules/three/../../etc/passwd", "/modules/left-pad/x.js",
        "/urdf/arm/a.urdf", "/urdf/pioneer", "/urdf/pioneer/../../etc/passwd", "/a/b.js", "/%2e%2e/x",
        "/a\\b", "/./app.js", "//etc/passwd",
        // Review of issue 20: /urdf/NAME/ served every file of the URDF's
        // folder (dot-files, symlinks out of it); meshes have /mesh/ now.
        "/urdf/pioneer/meshes/base.stl", "/urdf/pioneer/.ssh/id_rsa", "/urdf/pioneer/other.urdf"})
    EXPECT_EQ(Resolve(bad), "(refused)") << bad;
}

TEST(ContentTypeFor, KnowsThePagesFileTypes) {
  EXPECT_EQ(ContentTypeFor("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("three.module.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("r.URDF"), "application/xml");
  EXPECT_EQ(ContentTypeFor("blob"), "application/octet-stream");
}

}  // namespace
}  // namespace robotalk::web
