#include "postproc/report/report.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"

namespace naris::report {
namespace {

namespace fs = std::filesystem;

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const auto byte = [&](std::size_t k) {
      return k < bytes.size() ? static_cast<unsigned>(static_cast<unsigned char>(bytes[k])) : 0u;
    };
    const unsigned v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    out += digits[v >> 18 & 63];
    out += digits[v >> 12 & 63];
    out += i + 1 < bytes.size() ? digits[v >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? digits[v & 63] : '=';
  }
  return out;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot read the figure for the report", path.string());
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string num(const Json& j, int digits = 4) {
  return j.is_number() ? fmt::format("{:.{}g}", j.get<double>(), digits) : "";
}

std::string html_table(const Table& t) {
  std::string html = "<table><tr>";
  for (const std::string& h : t.header) html += fmt::format("<th>{}</th>", escape(h));
  html += "</tr>\n";
  for (const auto& row : t.rows) {
    html += "<tr>";
    for (const std::string& c : row) html += fmt::format("<td>{}</td>", escape(c));
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

}  // namespace

std::string markdown_table(const Table& t) {
  std::string md = "|";
  for (const std::string& h : t.header) md += fmt::format(" {} |", h);
  md += "\n|";
  for (std::size_t i = 0; i < t.header.size(); ++i) md += " --- |";
  md += "\n";
  for (const auto& row : t.rows) {
    md += "|";
    for (const std::string& c : row) md += fmt::format(" {} |", c);
    md += "\n";
  }
  return md;
}

void write_report(const Report& r, const fs::path& folder) {
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n"
      "<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}}"
      "table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #bbb;padding:3px "
      "8px;text-align:right}}th{{background:#eee}}td:first-child{{text-align:left}}"
      "img{{max-width:100%;display:block;margin:1em 0;border:1px solid #ddd}}"
      "pre{{background:#f6f6f6;padding:1em;overflow:auto}}</style></head><body>\n<h1>{}</h1>\n"
      "<p>naris {}</p>\n",
      escape(r.title), escape(r.title), escape(r.version));
  std::string md = fmt::format("# {}\n\nnaris {}\n", r.title, r.version);
  for (const Section& s : r.sections) {
    html += fmt::format("<h2>{}</h2>\n", escape(s.title));
    md += fmt::format("\n## {}\n", s.title);
    if (!s.text.empty()) {
      html += fmt::format("<p>{}</p>\n", escape(s.text));
      md += fmt::format("\n{}\n", s.text);
    }
    for (const Table& t : s.tables) {
      html += html_table(t);
      md += '\n';
      md += markdown_table(t);
    }
    for (const fs::path& f : s.figures) {
      const std::string alt = f.stem().string();
      html += fmt::format("<img alt=\"{}\" src=\"data:image/png;base64,{}\">\n", escape(alt),
                          base64(read_file(f)));
      md += fmt::format("\n![{}]({})\n", alt, fs::relative(f, folder).generic_string());
    }
  }
  if (!r.settings.empty()) {
    html += fmt::format("<h2>Settings</h2>\n<pre>{}</pre>\n", escape(r.settings));
    md += fmt::format("\n## Settings\n\n```yaml\n{}\n```\n", r.settings);
  }
  // Marks the page once every figure has decoded, for the browser test.
  html +=
      "<script>window.addEventListener('load',function(){var i=document.images,n=0;"
      "for(var k=0;k<i.length;++k)if(i[k].complete&&i[k].naturalWidth>0)++n;"
      "document.body.setAttribute('data-figures-loaded',n+'/'+i.length);});</script>\n"
      "</body></html>\n";
  write_text_file(folder / "report.html", html);
  write_text_file(folder / "report.md", md);
}

Report case_report(const fs::path& results, const std::string& name, const std::string& settings,
                   const std::string& version, bool traced) {
  Report r;
  r.title = fmt::format("naris report: {}", name);
  r.version = version;
  r.settings = settings;
  const Json sol = read_json_file(results / "solution" / "summary.json");
  Section flow{"Flow", "", {}, {}};
  Table t{{"quantity", "value"}, {}};
  auto add = [&](const std::string& q, const std::string& v) { t.rows.push_back({q, v}); };
  add("cells", num(sol["cells"], 10));
  add("Reynolds number", num(sol["reynolds"]));
  add("d_in = 4A/P (mm), " + sol.value("reynolds_defined_on", std::string("raw perimeter")),
      num(sol["inlet_hydraulic_diameter_mm"]));
  add("inlet speed U_in (m/s)", num(sol["inlet_speed_m_s"]));
  add("flow (mL/s)", num(sol["flow_ml_s"]));
  add("pressure drop (Pa)", num(sol["pressure_drop_pa"]));
  add("resistance (Pa·s/mL)", num(sol["resistance_pa_s_ml"]));
  add("maximum speed (m/s)", num(sol["max_speed_m_s"]));
  flow.tables.push_back(t);
  r.sections.push_back(flow);

  const fs::path planes = results / "planes" / "summary.json";
  if (fs::is_regular_file(planes)) {
    const Json p = read_json_file(planes);
    Section s{"Cross-sections", "", {}, {}};
    if (p.contains("inlet"))
      s.text = fmt::format(
          "Inlet: {} mm², perimeter {} mm smoothed at the voxel scale ({} mm as meshed), d_in {} "
          "mm smoothed, {} mm raw.",
          num(p["inlet"]["area_mm2"]), num(p["inlet"]["perimeter_mm"]),
          num(p["inlet"]["raw_perimeter_mm"]), num(p["inlet"]["hydraulic_diameter_mm"]),
          num(p["inlet"]["raw_hydraulic_diameter_mm"]));
    Table pt{{"plane", "pieces", "area (mm²)", "perimeter (mm)", "raw perimeter (mm)",
              "flux / inlet", "max speed (m/s)", "max speed (U_in)", "max axial (U_in)"},
             {}};
    for (const Json& q : p["planes"]) {
      const Json& a = q["all"];
      pt.rows.push_back({q["label"].get<std::string>(), num(q["pieces"]), num(a["area_mm2"]),
                         num(a["perimeter_mm"]), num(a["raw_perimeter_mm"]),
                         num(a.value("flux_to_inlet", Json()), 5), num(a["max_speed_m_s"]),
                         num(a["max_speed_u_in"]), num(a["max_axial_u_in"])});
    }
    s.tables.push_back(pt);
    for (const Json& f : p["figures"]) {
      const std::string file = f.get<std::string>();
      if (fs::path(file).extension() == ".png") s.figures.push_back(results / "planes" / file);
    }
    r.sections.push_back(s);
  }
  const fs::path trace = results / "trace" / "summary.json";
  if (traced && fs::is_regular_file(trace)) {
    const Json tr = read_json_file(trace);
    Section s{"Particle paths",
              fmt::format("{} particles, release: {}.", num(tr["particles"], 10),
                          tr.value("release", std::string())),
              {},
              {}};
    Table ft{{"group", "diameter (µm)", "released", "outlet", "wall", "max-time", "stagnated"}, {}};
    for (const Json& g : tr["per_group"])
      ft.rows.push_back({g["group"].get<std::string>(), num(g["diameter_um"]), num(g["released"]),
                         num(g["outlet"]), num(g["wall"]), num(g["max-time"]),
                         num(g["stagnated"])});
    s.tables.push_back(ft);
    for (const char* f : {"paths.png", "crossings.png"})
      if (fs::is_regular_file(results / "trace" / f)) s.figures.push_back(results / "trace" / f);
    r.sections.push_back(s);
  }
  return r;
}

}  // namespace naris::report
