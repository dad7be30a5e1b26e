#include "base/xml_scan.h"

#include <chrono>
#include <string>

#include <gtest/gtest.h>

namespace selfcal {
namespace {

XmlScanLimits Urdf() {
  XmlScanLimits limits;
  limits.kind = "a URDF";
  return limits;
}

std::string Nested(int depth) {
  std::string text = "<robot name=\"r\">\n<link name=\"a\"/>\n";
  for (int i = 0; i < depth; ++i) text += "<x>";
  for (int i = 0; i < depth; ++i) text += "</x>";
  return text + "\n</robot>\n";
}

TEST(XmlScan, AcceptsAWellFormedDocumentWithCommentsDeclarationsCdataAndQuotedGreaterThan) {
  const std::string text =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE robot [ <!ENTITY e \"x\"> ]>\n<!-- a <comment> -->\n"
      "<robot name=\"a > b\">\n  <link name='l'/>\n  <x><![CDATA[ <y> ]]></x>\n</robot>\n";
  EXPECT_TRUE(ScanXml(text, "r.urdf", Urdf()).ok()) << ScanXml(text, "r.urdf", Urdf()).message();
  EXPECT_TRUE(ScanXml(Nested(kMaxXmlDepth - 1), "r.urdf", Urdf()).ok());
}

// 100,000 nested elements crashed tinyxml (urdfdom) with a stack overflow: the scan refuses them at the
// limit, naming the file and the line, in well under a second.
TEST(XmlScan, RefusesDeepNestingNamingFileLineAndLimitQuickly) {
  const std::string text = Nested(100000);
  const auto start = std::chrono::steady_clock::now();
  const Status s = ScanXml(text, "deep.urdf", Urdf());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(s.message(), "deep.urdf:3: elements nested deeper than 64 levels, the limit for a URDF");
  EXPECT_LT(seconds, 0.2);
  EXPECT_FALSE(ScanXml(Nested(kMaxXmlDepth), "r.urdf", Urdf()).ok());
}

TEST(XmlScan, RefusesTooLargeTextNamingSizeAndLimit) {
  XmlScanLimits limits = Urdf();
  limits.max_bytes = 10;
  const Status s = ScanXml("<robot>  </robot>", "big.urdf", limits);
  EXPECT_EQ(s.message(), "big.urdf is 17 bytes, more than the limit of 10 bytes for a URDF");
}

TEST(XmlScan, RefusesUnclosedAndMismatchedMarkupByLine) {
  EXPECT_EQ(ScanXml("<a>\n<b>\n</a>", "f.xml", Urdf()).message(),
            "f.xml:3: closing tag </a> does not match <b> (line 2)");
  EXPECT_EQ(ScanXml("<a>\n<b/>\n", "f.xml", Urdf()).message(), "f.xml:1: element <a> is never closed");
  EXPECT_EQ(ScanXml("<a>\n<!-- x\n</a>", "f.xml", Urdf()).message(), "f.xml:2: a comment is never closed");
  EXPECT_EQ(ScanXml("<a>\n<b c=\"> \n", "f.xml", Urdf()).message(), "f.xml:2: unterminated tag `<b`: no `>` before the end of the file");
  EXPECT_EQ(ScanXml("<a/>\n</a>", "f.xml", Urdf()).message(), "f.xml:2: closing tag </a> without an open element");
}

TEST(XmlScan, RefusesInvalidUtf8AndRepeatedSiblingsWhenAsked) {
  XmlScanLimits limits = Urdf();
  limits.kind = "a camera file";
  limits.require_utf8 = true;
  limits.refuse_repeated_siblings = true;
  limits.repeatable = {"_"};
  EXPECT_EQ(ScanXml("<a>\n<b>\xff</b></a>", "c.xml", limits).message(),
            "c.xml:2: invalid UTF-8 (a camera file must be UTF-8)");
  EXPECT_EQ(ScanXml("<a>\n<b>1</b>\n<c/>\n<b>2</b></a>", "c.xml", limits).message(),
            "c.xml:4: element <b> appears twice in <a> (line 1); give each key once");
  EXPECT_TRUE(ScanXml("<a><d><_>1</_><_>2</_></d><e><b/></e><b/></a>", "c.xml", limits).ok());
  EXPECT_TRUE(ScanXml("<a>\n<b>\xc3\xa9</b></a>", "c.xml", limits).ok());
  // The mutation campaign's NUL byte inside an element (camera_visp-00185) was accepted.
  EXPECT_EQ(ScanXml(std::string("<a>\n<b>1\0 2</b></a>", 19), "c.xml", limits).message(),
            "c.xml:2: control character 0x00 (XML allows none but tab and line ends in a camera file)");
  EXPECT_FALSE(ScanXml("<a>\x01</a>", "c.xml", Urdf()).ok());
  EXPECT_TRUE(ScanXml("<a>\t1\r\n</a>", "c.xml", limits).ok());
  // ... and an XML declaration that does not open the file (the campaign swapped lines 1 and 2).
  EXPECT_EQ(ScanXml("<!-- c -->\n<?xml version=\"1.0\"?>\n<a/>", "c.xml", limits).message(),
            "c.xml:2: an XML declaration <?xml ...?> that does not open the file (it may only be its first text)");
  EXPECT_TRUE(ScanXml("<?xml version=\"1.0\"?>\n<a/>", "c.xml", limits).ok());
  EXPECT_TRUE(ScanXml("\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<a><?xml-stylesheet x?></a>", "c.xml", limits).ok());
  EXPECT_EQ(FirstInvalidUtf8Line("a\n\xc0\x80"), 2);  // overlong
  EXPECT_EQ(FirstInvalidUtf8Line("a\n\xed\xa0\x80"), 2);  // surrogate
  EXPECT_EQ(FirstInvalidUtf8Line("\xf0\x9f\x98\x80"), 0);
}

}  // namespace
}  // namespace selfcal
