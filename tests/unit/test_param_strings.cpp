// Text parameters (layer-name patterns, file names): any one line of text.
// The characters " < > & were refused until 7 December 2026, though `gi
// script` writes them as XML entities and MeshLab reads them back (a file
// "R&D.png" could not be named); line breaks and other control characters
// still are, as a script's attribute would turn them into spaces.
#include <gtest/gtest.h>

#include <string>

#include "gi/filters.h"
#include "gi/params.h"

namespace {

TEST(ParamStrings, OneLineOfAnyTextIsTaken) {
  const auto specs = gi::filterSpecs(gi::FilterKind::RayTracedView);
  gi::ParamValues v = gi::defaultValues(specs, 1.0);
  for (const std::string ok : {std::string("R&D <1> \"q\".png"), std::string("caf\xc3\xa9 \\ back.png"), std::string()}) {
    v.set("image_path", ok);
    EXPECT_FALSE(gi::validate(specs, v, 1.0).has_value()) << ok;
  }
  for (const std::string bad : {std::string("a\nb.png"), std::string("a\rb.png"), std::string("a\tb.png"), std::string("a\x7f.png"), std::string("a\x01.png")}) {
    v.set("image_path", bad);
    const auto e = gi::validate(specs, v, 1.0);
    ASSERT_TRUE(e.has_value()) << bad;
    EXPECT_EQ(*e, "parameter 'image_path' must be one line of text (no line breaks, tabs or control characters)");
  }
}

// The log and the cache key quote a text with its " and \ escaped, so two
// texts never give the same description.
TEST(ParamStrings, DescriptionsKeepTextsApart) {
  const auto specs = gi::filterSpecs(gi::FilterKind::RayTracedView);
  gi::ParamValues a = gi::defaultValues(specs, 1.0), b = a;
  a.set("image_path", std::string("x\", image_path=\"y"));
  b.set("image_path", std::string("x"));
  const std::string da = gi::describe(specs, a), db = gi::describe(specs, b);
  EXPECT_NE(da.find("image_path=\"x\\\", image_path=\\\"y\""), std::string::npos) << da;
  EXPECT_NE(da, db);
}

// `gi script` escapes them, so the .mlx stays well-formed.
TEST(ParamStrings, ScriptsEscapeThem) {
  gi::ScriptStep st{gi::FilterKind::RayTracedView, gi::defaultValues(gi::filterSpecs(gi::FilterKind::RayTracedView), 1.0)};
  st.values.set("image_path", std::string("R&D <1> \"q\".png"));
  const std::string x = gi::mlxScript({st}, 1.0);
  EXPECT_NE(x.find("value=\"R&amp;D &lt;1&gt; &quot;q&quot;.png\""), std::string::npos) << x;
}

}  // namespace
